"""Argument checks shared by the metrology core: a probability, a whole count."""

from __future__ import annotations

import numpy as np

__all__ = ["check_count", "check_probability"]


def check_probability(p, name: str = "coverage_probability") -> float:
    """*p* as a float strictly between 0 and 1 (a coverage probability, JCGM 100 6.2.2; JCGM 101 3.13).

    Raises
    ------
    ValueError
        Naming *name*, the value and the allowed range.
    """
    if isinstance(p, bool) or not isinstance(p, (int, float)) or not 0.0 < p < 1.0:
        raise ValueError(f"{name} = {p!r}: must lie strictly between 0 and 1")
    return float(p)


def check_count(value, name: str, minimum: int = 1) -> int:
    """*value* as an int, which must be a whole number ``>= minimum`` (a count of trials or blocks).

    Raises
    ------
    ValueError
        Naming *name*, the value and the minimum.
    """
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise ValueError(f"{name} = {value!r}: expected a whole number >= {minimum}")
    return int(value)
