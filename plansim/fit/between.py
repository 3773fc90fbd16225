"""Noise between segments: what the segment means show beyond the predicted noise, and repeated settings.

:func:`between_segment_noise` estimates, per channel, a variance of the segment means beyond the prediction (slow
noise the segments are too short to show), with a correlation exp(−|Δt|/τ) between segments, from a fit's
residuals by restricted maximum likelihood, and keeps it where the likelihood ratio against none passes
:data:`BETWEEN_LR_THRESHOLD` (docs/fitting.md, "Noise between segments"). :func:`between_segments` compares the
scatter of repeated settings (the two headings of JJF 2003's 12 positions) with its prediction, split into the
noise's and the table's parts (issue: the table's position errors never show in within-segment scatter).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.fit.budget import CHI2_FLAG_PROBABILITY, Sources
from plansim.kernels.layout import CHANNELS
from plansim.schedule.segments import Schedule


@dataclass(frozen=True)
class BetweenSegmentNoise:
    """Noise of the segment means beyond the predicted, per channel (gx gy gz ax ay az), from the fit's residuals.

    ``variance`` (6,) σ_c², SI², zero where the residuals show none; ``correlation_time`` (6,) τ_c, s, of its
    correlation exp(−|t_s − t_r|/τ_c) between segments (0: independent); ``dof`` (6,) the degrees of freedom
    of σ_c²; ``ratio`` (6,) the mean of r_i²/d_i over the channel's fitted rows (1 when the prediction holds).
    """

    variance: np.ndarray
    correlation_time: np.ndarray
    dof: np.ndarray
    ratio: np.ndarray

    def covariance(self, c: int, times: np.ndarray) -> np.ndarray:
        """(S, S) covariance of channel *c*'s term over segments at middle *times* (s)."""
        return self.variance[c] * time_correlation(times, self.correlation_time[c])


#: the likelihood-ratio statistic 2·Δlog L (against σ² = 0) above which the between-segment noise is taken:
#: calibrated by simulation — 5 % of the channels of recordings with no such noise (scenario linear_gaussian,
#: 40 recordings × 6 channels) exceed 2.95; the asymptotic ½χ²₀ + ½χ²₁ mixture has its 95 % point at 2.71,
#: and the best of the six correlation times adds a little
BETWEEN_LR_THRESHOLD = 3.0


#: correlation times tried for the between-segment noise, s (0: independent segments); the likelihood picks one
BETWEEN_CORRELATION_TIMES = (0.0, 30.0, 100.0, 300.0)


def time_correlation(times: np.ndarray, tau: float) -> np.ndarray:
    """(S, S) exp(−|t_s − t_r|/τ) between segments at middle *times* (s); the identity for τ ≤ 0."""
    lag = np.abs(np.asarray(times, dtype=float)[:, None] - np.asarray(times, dtype=float)[None, :])
    return np.eye(lag.shape[0]) if tau <= 0 else np.exp(-lag / tau)


def between_segment_noise(residual: np.ndarray, V: np.ndarray, hat: np.ndarray, rows: np.ndarray,
                          times: np.ndarray, coupled: bool = False) -> BetweenSegmentNoise:
    """The noise σ_c² (correlated over τ_c in time) of each channel's segment means that the residuals show
    beyond V.

    Segment means carry noise their own samples cannot show: a bias-instability process whose correlation
    time is longer than a segment moves each segment's mean by up to its stationary σ, while within a 30 s
    segment it hardly varies, so neither the scatter nor the Allan deviation of the segments sees it. The
    residuals *between* segments do. Model for channel c: an added term b_s with Cov(b_s, b_r) =
    σ_c²·exp(−|t_s − t_r|/τ_c) (t the segments' middle times); the residuals r = R·(e + b), R = I − H (H
    the fit's hat matrix), have covariance Ω = R_c V R_cᵀ + σ_c²·R_cc Σ(τ_c) R_ccᵀ on the channel's fitted
    rows. σ_c² is the restricted maximum likelihood on the residual subspace (the eigenvectors of R V Rᵀ
    that carry variance), for each τ of :data:`BETWEEN_CORRELATION_TIMES`, and τ_c the one of largest
    likelihood; σ_c² = 0 when the data show nothing beyond V. ν_c = Σ(1 − H_ii) over the channel's rows.

    This is the "dark uncertainty" of interlaboratory comparisons (a random effect estimated from the
    scatter beyond the stated uncertainties), per channel and correlated in time; it enters the segment
    means' covariance as a Type A input. docs/fitting.md.

    *coupled*: the fit's per-pose nuisance parameters (the tilts of poses placed by hand) couple the channels'
    residuals — a pose's tilt moves all three accelerometers — so one channel's term shows in another's rows,
    and each channel's own estimate counts it again there. Then the channels that took a term are estimated
    once more together (:func:`_joint_between_variances`: the restricted likelihood of every fitted row at
    once, each τ_c held). On a simulated 30-pose hand session with an accelerometer K2 on ax alone, the
    channel-by-channel terms were 0.64, 1.91 and 1.34 mg on ax, ay and az; together 0.59, 0.06 and 0.10 mg
    (test).
    """
    R = np.eye(residual.size) - hat
    C = R @ V @ R.T
    variance, taus, dof, ratio = np.zeros(6), np.zeros(6), np.zeros(6), np.ones(6)
    for c in range(6):
        segments = np.flatnonzero(rows[:, c])
        idx = segments * 6 + c
        if idx.size < 2:
            continue
        block = C[np.ix_(idx, idx)]
        d = np.diag(block)
        if not np.all(d > 0):
            continue
        ratio[c] = float(np.mean(residual[idx] ** 2 / d))
        dof[c] = max(float(np.sum(1.0 - np.diag(hat)[idx])), 1.0)
        values, vectors = np.linalg.eigh(block)
        keep = values > 1e-9 * values.max()
        U = vectors[:, keep] / np.sqrt(values[keep])  # whitens the predicted residual covariance
        y = U.T @ residual[idx]
        Rcc = R[np.ix_(idx, idx)]
        scale = float(np.median(d))  # σ² is searched relative to the predicted residual variance
        best = (0.0, 0.0, -0.5 * float(y @ y))  # σ² = 0: the prediction alone
        for tau in BETWEEN_CORRELATION_TIMES:
            A = U.T @ Rcc @ time_correlation(times[segments], tau) @ Rcc.T @ U
            lam, Q = np.linalg.eigh(A)
            lam = np.maximum(lam, 0.0)
            z2 = (Q.T @ y) ** 2
            if lam.max() <= 0:
                continue
            s2, log_likelihood = _reml_variance(lam, z2, scale)  # relative to the predicted scale
            if log_likelihood > best[2]:
                best = (s2, tau, log_likelihood)
        gain = best[2] + 0.5 * float(y @ y)  # log-likelihood ratio against σ² = 0
        if best[0] > 0 and 2.0 * gain > BETWEEN_LR_THRESHOLD:
            variance[c], taus[c] = best[0], best[1]
    if coupled and np.count_nonzero(variance) > 1:
        variance = _joint_between_variances(residual, C, R, rows, times, variance, taus)
    return BetweenSegmentNoise(variance, taus, dof, ratio)


#: coordinate-ascent sweeps of :func:`_joint_between_variances`
JOINT_BETWEEN_SWEEPS = 4

#: the repeated settings' verdicts (:attr:`BetweenSegments.verdict`; a χ² test at CHI2_FLAG_PROBABILITY two-sided)
SCATTER_MORE = "the data scatter more than predicted"
SCATTER_LESS = "the data scatter less than predicted"
SCATTER_CONSISTENT = "consistent"


def _joint_between_variances(residual, C, R, rows, times, variance, taus) -> np.ndarray:
    """The between-segment variances of the channels that took one, re-estimated together: the restricted
    likelihood of every fitted row's residual, covariance C + Σ_c σ_c² R E_c Σ(τ_c) E_cᵀ Rᵀ (E_c placing channel
    c's segments), maximised over the σ_c² by coordinate ascent (:data:`JOINT_BETWEEN_SWEEPS` sweeps, each a
    one-dimensional search as the channel-by-channel one (:func:`_reml_variance`), the others held), each τ_c as
    that estimate chose it."""
    on = np.flatnonzero(variance > 0)
    values, vectors = np.linalg.eigh(0.5 * (C + C.T))
    keep = values > 1e-9 * values.max()
    U = vectors[:, keep] / np.sqrt(values[keep])
    y = U.T @ residual
    shapes = {}
    for c in on:
        segments = np.flatnonzero(rows[:, c])
        G = U.T @ R[:, segments * 6 + c]
        shapes[c] = G @ time_correlation(times[segments], taus[c]) @ G.T
    out = np.array(variance, dtype=float)
    for _ in range(JOINT_BETWEEN_SWEEPS):
        for c in on:
            others = np.eye(y.size) + sum(out[k] * shapes[k] for k in on if k != c)
            b_values, b_vectors = np.linalg.eigh(others)
            L = (b_vectors / np.sqrt(b_values)) @ b_vectors.T
            lam, Q = np.linalg.eigh(L @ shapes[c] @ L)
            lam = np.maximum(lam, 0.0)
            if lam.max() <= 0:
                out[c] = 0.0
                continue
            z2 = (Q.T @ (L @ y)) ** 2
            s2, log_likelihood = _reml_variance(lam, z2, 1.0 / lam.max())
            out[c] = s2 if log_likelihood > -0.5 * float(np.sum(z2)) else 0.0  # against σ_c² = 0
    return out


def _reml_variance(lam: np.ndarray, z2: np.ndarray, scale: float) -> tuple[float, float]:
    """The σ² that maximises the restricted log-likelihood −½ Σ_i [log(1 + σ²λ_i) + z_i²/(1 + σ²λ_i)] of a whitened
    residual with squared components *z2* along the eigenvectors of an added term of eigenvalues *lam*, searched
    from 12 decades below *scale* to 6 above; (σ², its log-likelihood). σ² = 0 gives −½ Σ z_i²."""
    from scipy.optimize import minimize_scalar

    def negative_log_likelihood(log_ratio):
        s2 = scale * math.exp(log_ratio)
        return 0.5 * float(np.sum(np.log1p(s2 * lam) + z2 / (1.0 + s2 * lam)))

    result = minimize_scalar(negative_log_likelihood, bounds=(-12 * math.log(10), 6 * math.log(10)), method="bounded")
    return scale * math.exp(result.x), -float(result.fun)


def add_between_segment_noise(sources: Sources, slow: BetweenSegmentNoise, rows: np.ndarray,
                              times: np.ndarray) -> None:
    """Independent Type A inputs (kind ``between``) carrying each channel's between-segment covariance."""
    S = rows.shape[0]
    for c in np.flatnonzero(slow.variance > 0):
        segments = np.flatnonzero(rows[:, c])
        values, vectors = np.linalg.eigh(slow.covariance(c, times[segments]))
        for value, vector in zip(values, vectors.T):
            if value > 1e-12 * values.max():
                column = np.zeros((S, 6))
                column[segments, c] = vector
                sources.add(column.ravel(), math.sqrt(value), slow.dof[c], "between")


@dataclass(frozen=True)
class BetweenSegments:
    """Repeated settings of one channel: the data's scatter between segments against the prediction."""

    channel: str
    groups: int
    dof: int
    observed_sd: float  # r.m.s. within-group deviation of the residuals (data), SI
    predicted_sd: float  # the same predicted from the noise model and the Type B table errors
    predicted_noise_sd: float  # ... from the noise alone
    predicted_table_sd: float  # ... from the per-setting table errors alone
    component_sd: float  # between-segment component from the data: sqrt(max(observed² − noise part, 0))
    ratio: float  # observed² / predicted²
    verdict: str


def repeat_groups(schedule: Schedule) -> list[list[int]]:
    """Segments that repeat one setting (same up-axis, rate and rate axis; the heading may differ)."""
    groups: dict[tuple, list[int]] = {}
    for k, s in enumerate(schedule.segments):
        if s.orientation != "known":  # a pose placed by hand is not a repeat of a setting
            continue
        key = (s.up, s.rate, s.rate_axis if s.is_rotating else None)
        groups.setdefault(key, []).append(k)
    return [g for g in groups.values() if len(g) >= 2]


def between_segments(schedule: Schedule, residual: np.ndarray, residual_cov: np.ndarray, project: np.ndarray,
                     sources: Sources) -> tuple[BetweenSegments, ...]:
    """Within-group scatter of the residuals of repeated settings, per channel, against its prediction.

    For channel c, Q_c projects the residuals of each group onto their deviations from the group's mean;
    the observed sum of squares is rᵀQ_c r, its expectation under the model trace(Q_c·R V Rᵀ) with
    R = I − H (H the fit's hat matrix), split into the noise's and the table's parts. The data's
    between-segment component beyond the noise is sqrt(max(observed − noise part, 0)/ν).
    """
    from scipy.special import chdtrc

    groups = repeat_groups(schedule)
    if not groups:
        return ()
    n = residual.size
    V_noise = sources.covariance({"noise"})
    V_table = sources.covariance({"table", "angle"})
    out = []
    for c, name in enumerate(CHANNELS):
        Q = np.zeros((n, n))
        dof = 0
        for g in groups:
            idx = np.array(g) * 6 + c
            block = np.eye(len(g)) - 1.0 / len(g)
            Q[np.ix_(idx, idx)] = block
            dof += len(g) - 1
        observed = float(residual @ Q @ residual)
        expected = float(np.trace(Q @ residual_cov))
        noise_part = float(np.trace(Q @ project @ V_noise @ project.T))
        table_part = max(float(np.trace(Q @ project @ V_table @ project.T)), 0.0)
        noise_part = max(noise_part, 0.0)
        ratio = observed / expected if expected > 0 else math.inf
        upper = float(chdtrc(dof, dof * ratio)) if math.isfinite(ratio) else 0.0
        if upper < CHI2_FLAG_PROBABILITY / 2:
            verdict = SCATTER_MORE
        elif upper > 1 - CHI2_FLAG_PROBABILITY / 2:
            verdict = SCATTER_LESS
        else:
            verdict = SCATTER_CONSISTENT
        observed, expected = max(observed, 0.0), max(expected, 0.0)  # quadratic forms, ≥ 0 but for rounding
        out.append(BetweenSegments(name, len(groups), dof, math.sqrt(observed / dof), math.sqrt(expected / dof),
                                   math.sqrt(noise_part / dof), math.sqrt(table_part / dof),
                                   math.sqrt(max(observed - noise_part, 0.0) / dof), ratio, verdict))
    return tuple(out)
