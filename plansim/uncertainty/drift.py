"""Drift of the sensors as a covariance of the segment means (JCGM 100 5.2.2, correlated inputs).

The simulator's drift model — first-order Gauss–Markov bias instability, Gauss–Markov drift and
random walk, advanced exactly every drift update interval and held in between — gives the
covariance of every pair of segment means of a channel exactly, settling gaps included
(:func:`drift_covariance`).
"""

from __future__ import annotations

import numpy as np

from plansim.config import Scenario
from plansim.kernels.drift import held_process_covariance
from plansim.kernels.layout import NOISE_BIAS_INSTABILITY, NOISE_MARKOV, NOISE_RANDOM_WALK
from plansim.simulate.arguments import drift_coefficient_table, kernel_arguments

__all__ = ["drift_covariance"]


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
                                          (noise[c, NOISE_RANDOM_WALK], 0.0))):  # τ = 0: a random walk
            if sigma > 0.0:
                held_process_covariance(np.ascontiguousarray(table[:, p, :]), gaps, float(sigma), float(tau), out[c])
    return out
