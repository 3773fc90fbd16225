"""JCGM 101:2008 7.7: coverage intervals from the ordered Monte Carlo values."""

from __future__ import annotations

import math

import numpy as np

from plansim.uncertainty.metrology.checks import check_probability

__all__ = ["coverage_intervals"]


def coverage_intervals(values, coverage_probability: float = 0.95) -> dict:
    """Probabilistically symmetric and shortest coverage intervals, JCGM 101 7.7.

    With the ``M`` values sorted, ``q = pM`` if that is an integer, else ``⌊pM + ½⌋``. The
    probabilistically symmetric interval (7.7.1) is ``[y_(r), y_(r+q)]`` with ``r = (M − q)/2`` if
    that is an integer, else ``⌊(M − q + 1)/2⌋``; the shortest (7.7.2) is the ``[y_(r), y_(r+q)]``
    of least length over ``r = 1 … M − q`` (1-based order statistics).

    Parameters
    ----------
    values : (M,) or (M, n) array_like
        Monte Carlo values of one or several outputs (columns).
    coverage_probability : float
        ``p``.

    Returns
    -------
    dict
        ``low``, ``high`` (symmetric) and ``shortest_low``, ``shortest_high``, each of shape (n,)
        (or floats for 1-D input).

    Raises
    ------
    ValueError
        A shape other than (M,) or (M, n) with M >= 2, or too few values for the probability
        (``q >= M``; JCGM 101 7.2.2 asks ``M >> 1/(1 − p)``).
    """
    p = check_probability(coverage_probability)
    y = np.asarray(values, dtype=float)
    one = y.ndim == 1
    if one:
        y = y[:, None]
    if y.ndim != 2 or y.shape[0] < 2:
        raise ValueError(f"values: shape {np.shape(values)}; expected (M,) or (M, n) with M >= 2")
    m = y.shape[0]
    pm = p * m
    q = int(round(pm)) if abs(pm - round(pm)) < 1e-9 else int(math.floor(pm + 0.5))
    if q >= m:
        raise ValueError(f"{m} values are too few for a {p:.0%} coverage interval (JCGM 101 7.2.2: M >> 1/(1 − p))")
    rest = m - q
    r = rest // 2 if rest % 2 == 0 else (rest + 1) // 2
    ordered = np.sort(y, axis=0)
    low, high = ordered[r - 1], ordered[r - 1 + q]
    lengths = ordered[q:] - ordered[:-q]  # r = 1 … M − q: y_(r+q) − y_(r)
    best = np.argmin(lengths, axis=0)
    cols = np.arange(y.shape[1])
    short_low, short_high = ordered[best, cols], ordered[best + q, cols]
    out = {"low": low, "high": high, "shortest_low": short_low, "shortest_high": short_high}
    if one:
        out = {k: float(v[0]) for k, v in out.items()}
    return out
