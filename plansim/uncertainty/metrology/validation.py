"""JCGM 101:2008 §8: validation of the GUM uncertainty framework by the Monte Carlo method."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plansim.uncertainty.metrology.monte_carlo import DEFAULT_DIGITS, numerical_tolerance

__all__ = ["ValidationOutcome", "validate_gum"]


@dataclass(frozen=True)
class ValidationOutcome:
    """JCGM 101 8.1 comparison of the GUM interval ``y ± U_p`` with the MCM interval, per output.

    Attributes
    ----------
    delta : (n,) ndarray
        ``δ`` of the GUM ``u(y)`` (7.9.2, 8.1.1).
    d_low, d_high : (n,) ndarray
        ``|y − U_p − y_low|`` and ``|y + U_p − y_high|`` (8.1.2).
    validated : (n,) ndarray of bool
        ``d_low ≤ δ`` and ``d_high ≤ δ`` (8.1.3).
    """

    delta: np.ndarray
    d_low: np.ndarray
    d_high: np.ndarray
    validated: np.ndarray


def validate_gum(gum_estimate, gum_expanded, gum_standard_uncertainty, mcm_low, mcm_high,
                 digits: int = DEFAULT_DIGITS) -> ValidationOutcome:
    """Validation of the GUM uncertainty framework using MCM, JCGM 101 8.

    Parameters
    ----------
    gum_estimate, gum_expanded, gum_standard_uncertainty : array_like
        ``y``, ``U_p`` and ``u(y)`` from the GUM (JCGM 100).
    mcm_low, mcm_high : array_like
        The MCM coverage interval (probabilistically symmetric, JCGM 101 7.7.1).
    digits : int
        ``n_dig`` of ``δ`` (7.9.2).

    Returns
    -------
    ValidationOutcome

    Raises
    ------
    ValueError
        Arrays of different shapes, non-finite ``u``, or a bad *digits*.
    """
    y, U, u, low, high = (np.atleast_1d(np.asarray(x, dtype=float))
                          for x in (gum_estimate, gum_expanded, gum_standard_uncertainty, mcm_low, mcm_high))
    shapes = {x.shape for x in (y, U, u, low, high)}
    if len(shapes) != 1:
        raise ValueError(f"validate_gum: the arrays have different shapes {sorted(shapes)}")
    delta = np.atleast_1d(numerical_tolerance(u, digits))
    d_low = np.abs(y - U - low)
    d_high = np.abs(y + U - high)
    return ValidationOutcome(delta=delta, d_low=d_low, d_high=d_high, validated=(d_low <= delta) & (d_high <= delta))
