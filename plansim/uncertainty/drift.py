"""Drift of the sensors as a covariance of the segment means (JCGM 100 5.2.2, correlated inputs).

The simulator's drift model — first-order Gauss–Markov bias instability, Gauss–Markov drift and
random walk, advanced exactly every drift update interval and held in between — gives the
covariance of every pair of segment means of a channel exactly, settling gaps included
(:func:`drift_covariance`).
"""

from __future__ import annotations

import math

import numpy as np

from plansim.config import Scenario
from plansim.kernels.layout import NOISE_BIAS_INSTABILITY, NOISE_MARKOV, NOISE_RANDOM_WALK
from plansim.simulate.arguments import drift_coefficient_table, kernel_arguments

__all__ = ["drift_covariance"]


def _process_covariance(coefficients: np.ndarray, gaps: np.ndarray, sigma: float, tau: float | None) -> np.ndarray:
    """Covariance (S, S) of the segment means of one held drift process (exact state recursion).

    ``coefficients`` (S, 5): unit-σ ``a, c, L11, L21, L22`` of
    :func:`plansim.kernels.drift.drift_coefficients` (``mean = a·x0 + σL11 z1``,
    ``end = c·x0 + σ(L21 z1 + L22 z2)``); ``gaps`` (S,): settling before each segment, over which the
    state is advanced exactly (φ = exp(−Δ/τ), or a random walk when ``tau`` is None).
    """
    n_seg = len(gaps)
    variance = sigma**2 if tau is not None else 0.0  # Gauss–Markov stationary at the start, walks at 0
    with_means = np.zeros(n_seg)  # Cov(state, mean_j) for the segments done so far
    cov = np.zeros((n_seg, n_seg))
    for s in range(n_seg):
        gap = gaps[s]
        if gap > 0.0:
            if tau is None:
                variance += sigma**2 * gap
            else:
                phi = math.exp(-gap / tau)
                variance = phi**2 * variance + sigma**2 * (1.0 - phi**2)
                with_means *= phi
        a, c, l11, l21, l22 = coefficients[s]
        cov[s, :s] = a * with_means[:s]
        cov[:s, s] = cov[s, :s]
        cov[s, s] = a**2 * variance + sigma**2 * l11**2
        end_with_means = c * with_means
        end_with_means[s] = c * a * variance + sigma**2 * l11 * l21
        variance = c**2 * variance + sigma**2 * (l21**2 + l22**2)
        with_means = end_with_means
    return cov


def drift_covariance(scenario: Scenario, arguments: dict | None = None) -> np.ndarray:
    """Covariance of the drift part of every segment mean, ``(6, S, S)`` per channel gx … az.

    Derived from the model the simulator uses (:mod:`plansim.kernels.drift`): first-order
    Gauss–Markov bias instability (σ from :func:`plansim.simulate.arguments.bias_instability_sigma`,
    correlation time ``bias_instability_correlation_time``), Gauss–Markov drift
    (``*_markov_sigma``, ``markov_correlation_time``) and random walk, each advanced exactly every
    ``drift_update_interval`` and held in between; Gauss–Markov processes stationary at the start
    of the test, random walks starting at zero. The recursion over the segments (settling gaps
    included) gives the covariance exactly; channels and processes are independent.

    Parameters
    ----------
    scenario : Scenario
    arguments : dict, optional
        :func:`plansim.simulate.arguments.kernel_arguments` of *scenario*, if the caller has them.

    Returns
    -------
    (6, S, S) ndarray
        In (rad/s)² for the gyros, (m/s²)² for the accelerometers.
    """
    noise = (kernel_arguments(scenario) if arguments is None else arguments)["noise"]  # (6, 4): NOISE_COLUMNS
    table = drift_coefficient_table(scenario)  # (S, 3, 5): bias instability, Gauss–Markov, random walk
    gaps = np.array([s.settle for s in scenario.schedule.segments], dtype=float)
    n = scenario.noise
    n_seg = len(gaps)
    out = np.zeros((6, n_seg, n_seg))
    for c in range(6):
        for p, (sigma, tau) in enumerate(((noise[c, NOISE_BIAS_INSTABILITY], n.bias_instability_correlation_time),
                                          (noise[c, NOISE_MARKOV], n.markov_correlation_time),
                                          (noise[c, NOISE_RANDOM_WALK], None))):
            if sigma > 0.0:
                out[c] += _process_covariance(table[:, p, :], gaps, float(sigma), tau)
    return out
