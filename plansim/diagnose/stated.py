"""Scatter beyond the stated noise: the segment means against the slow noise the lab states for its unit.

The segment-level lack of fit (:func:`plansim.diagnose.scores.lack_of_fit`) weighs the residual against a noise
model estimated from the same recording: the samples' Allan deviation (white noise N, bias instability B, rate
random walk K) and the noise between segments that the residuals show beyond it
(:func:`plansim.fit.between.between_segment_noise`). Both take up whatever the residual holds that looks like
noise. A slow effect the model lacks — a disturbance with a period of minutes, a scale factor that is wrong at one
rate, a bias that follows the temperature — inflates them, and the tests, weighed against the inflated noise, no
longer see it (docs/closing-the-loop.md, "Excess scatter"). A recording that repeats no setting at distant times
cannot tell such an effect from slow noise by itself. What can is a bound from outside it: the noise the lab
states for its unit (``plansim diagnose --scenario``: its ``[mimu.noise]``, as plansim simulates it,
:class:`plansim.fit.noise.StatedSlowNoise`).

**The test.** Under H0 the segment means' errors have the fit's predicted covariance V (white noise from the
samples, the quantiser, the table's and fixture's Type B errors, the site) with its slow part replaced: the
Allan fit's B and K over each segment (:func:`plansim.fit.noise.allan_slow_variance`) out, and the stated slow
noise averaged over the segments (:meth:`~plansim.fit.noise.StatedSlowNoise.mean_covariance`), taken up to
:data:`STATED_NOISE_MARGIN` times in standard deviation, in. The residual of the fit, r = R·e with
R = I − D (W D)⁺ W (D the design at the solution, W the fit's whitening), then has covariance C₀ = R V₀ Rᵀ to first
order, and for each channel c the quadratic form

    Q_c = r_cᵀ C₀,cc⁺ r_c

over the channel's fitted segments is χ² with rank(C₀,cc) degrees of freedom under H0 (Gaussian errors): its
p-value is analytic, and the channels' are combined by Bonferroni at the test's level. Q_c/ν is the mean square
of the residual in units of what the statement allows. Where the unit's slow noise is at or below the statement,
the test's false-alarm rate is at most its level; where the margin covers it, far below.

Not tested: a channel whose means' noise is mostly an undithered quantiser's
(:func:`plansim.diagnose.scores.undithered_channels`), whose V describes their scatter only roughly, as the step
test leaves it out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from plansim.fit.noise import StatedSlowNoise, allan_slow_variance, channel_kind
from plansim.kernels.layout import CHANNELS

#: the stated slow noise is a bound up to this factor in standard deviation (4 in variance): a data sheet's bias
#: instability is a typical value, not a unit's largest, and the Gauss–Markov process that stands for it holds a
#: flicker floor's long-term wander only up to its correlation time
STATED_NOISE_MARGIN = 2.0


@dataclass(frozen=True)
class StatedNoiseTest:
    """:func:`stated_noise_test`'s outcome."""

    level: float  # the test's level (its share of the diagnosis's α)
    margin: float  # the statement is taken up to this factor in s.d.
    source: str  # where the statement comes from
    channels: tuple[dict, ...]  # per channel tested: channel, statistic Q, dof ν, p_value, sd_ratio √(Q/ν), stated
    p_value: float  # Bonferroni over the channels tested
    flagged: bool

    def flagged_channels(self) -> list[dict]:
        """The channels whose own p is below the level over the number tested."""
        m = max(len(self.channels), 1)
        return [dict(item) for item in self.channels if item["p_value"] < self.level / m]

    def as_json(self) -> dict:
        return {"level": self.level, "margin": self.margin, "source": self.source, "p_value": self.p_value,
                "flagged": self.flagged, "channels": [dict(item) for item in self.channels]}


def stated_noise_test(fit, stated: StatedSlowNoise, durations, *, alpha: float, excluded=frozenset(),
                      margin: float = STATED_NOISE_MARGIN) -> StatedNoiseTest | None:
    """The segment means of *fit* against the slow noise *stated* for the unit (module docstring).

    Parameters
    ----------
    fit : plansim.fit.FitResult
        A fit with its internals (``covariance_predicted``, ``design``, ``whitening``).
    stated : StatedSlowNoise
    durations : (S,) array
        Each used segment's duration, s (the fit's segments, in their order).
    alpha : float
        The test's level (0 < alpha < 1).
    excluded : set of int
        Channels not tested (the undithered ones).
    margin : float
        The statement is taken up to this factor in standard deviation (≥ 1).

    Returns
    -------
    StatedNoiseTest, or None where no channel can be tested.
    """
    from scipy.stats import chi2

    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r}: must be between 0 and 1")
    if not margin >= 1:
        raise ValueError(f"margin = {margin!r}: must be >= 1 (the statement taken up to that factor in s.d.)")
    if not isinstance(stated, StatedSlowNoise):
        raise TypeError(f"stated: expected a plansim.fit.noise.StatedSlowNoise, got {type(stated).__name__}")
    rows = np.asarray(fit.fitted_rows, dtype=bool)
    S = rows.shape[0]
    durations = np.asarray(durations, dtype=float)
    if durations.shape != (S,) or not np.all(durations > 0):
        raise ValueError(f"durations: {S} positive values expected (the fit's segments, s); got shape "
                         f"{durations.shape}")
    if fit.covariance_predicted is None or fit.design is None or fit.whitening is None:
        raise ValueError("fit: has no internals (covariance_predicted, design, whitening); fit it with "
                         "plansim.fit.fit_recording")
    times = np.asarray(fit.segment_times, dtype=float)
    V0 = np.array(fit.covariance_predicted, dtype=float)
    slow = np.array([[allan_slow_variance(ch, T) for ch in fit.noise.channels] for T in durations]).ravel()
    diagonal = np.diag_indices(6 * S)
    V0[diagonal] = np.maximum(V0[diagonal] - slow, 0.0)
    for c in range(6):
        idx = np.arange(S) * 6 + c
        V0[np.ix_(idx, idx)] += margin**2 * stated.mean_covariance(c, times, durations)
    D, W = np.asarray(fit.design, dtype=float), np.asarray(fit.whitening, dtype=float)
    R = np.eye(6 * S) - D @ np.linalg.pinv(W @ D) @ W
    C0 = R @ V0 @ R.T
    r = np.asarray(fit.residuals, dtype=float).ravel()
    out = []
    for c in range(6):
        if c in excluded or np.count_nonzero(rows[:, c]) < 2:
            continue
        idx = np.flatnonzero(rows[:, c]) * 6 + c
        block = C0[np.ix_(idx, idx)]
        values, vectors = np.linalg.eigh(0.5 * (block + block.T))
        keep = values > 1e-9 * max(values.max(), 1e-300)
        if not np.any(keep):
            continue
        Q = float(np.sum((vectors[:, keep].T @ r[idx]) ** 2 / values[keep]))
        dof = int(np.count_nonzero(keep))
        out.append({"channel": CHANNELS[c], "statistic": Q, "dof": dof, "p_value": float(chi2.sf(Q, dof)),
                    "sd_ratio": math.sqrt(Q / dof), "stated": stated.describe(c),
                    "kind": channel_kind(c)})
    if not out:
        return None
    p = min(1.0, len(out) * min(item["p_value"] for item in out))
    return StatedNoiseTest(level=alpha, margin=margin, source=stated.source, channels=tuple(out), p_value=p,
                           flagged=bool(p < alpha))
