"""Coverage of the true value: how often a stated interval contains it, and the verdict on the statement.

A simulation knows the true value of its measurand, so a stated expanded uncertainty ``U`` with
coverage probability ``p`` (JCGM 100 6.2; JCGM 101 3.12-3.13) can be checked directly: the fraction
of trials with ``|E| ≤ U`` (``E`` = estimate − truth) should be ``p`` within the binomial sampling
error of that fraction.

- :func:`coverage_against_truth` — that fraction, per output;
- :func:`coverage_tolerance` — ``z`` binomial standard deviations of an observed coverage;
- :func:`minimum_trials_to_judge` — how many trials a verdict needs before it can tell;
- :func:`coverage_verdict` — under-stated, over-stated by a factor, supported, or too few trials to judge.
"""

from __future__ import annotations

import math

import numpy as np

from plansim.uncertainty.metrology.checks import check_count

__all__ = ["COVERAGE_Z", "OVERSTATEMENT_FACTOR", "coverage_against_truth", "coverage_tolerance", "coverage_verdict",
           "minimum_trials_to_judge"]

#: Binomial standard deviations allowed between an observed coverage and its nominal value in a verdict.
COVERAGE_Z = 3.0
#: A statement that covers more than its probability is called over-stated only when it is more than
#: this factor wider than the half-width the Monte Carlo needs.
OVERSTATEMENT_FACTOR = 2.0


def coverage_against_truth(errors, half_width) -> np.ndarray:
    """Fraction of trials whose interval ``estimate ± half_width`` contains the truth (``|E| ≤ U``).

    Parameters
    ----------
    errors : (M, n) array_like
        ``estimate − truth`` per trial and output.
    half_width : (n,) array_like
        The expanded uncertainty ``U`` stated for each output (``nan``: no statement → ``nan``).

    Returns
    -------
    (n,) ndarray
    """
    e = np.asarray(errors, dtype=float)
    u = np.asarray(half_width, dtype=float)
    if e.ndim != 2 or u.shape != (e.shape[1],):
        raise ValueError(f"errors shape {e.shape} and half_width shape {u.shape}: expected (M, n) and (n,)")
    covered = np.mean(np.abs(e) <= np.where(np.isnan(u), 0.0, u)[None, :], axis=0)
    return np.where(np.isnan(u), np.nan, covered)


def coverage_tolerance(n: int, coverage_probability: float = 0.95, z: float = COVERAGE_Z) -> float:
    """``z·sqrt(p(1 − p)/n)``: *z* binomial standard deviations of a coverage observed in *n* trials.

    Parameters
    ----------
    n : int
        Trials (or pooled errors) the coverage is counted over, >= 1.
    coverage_probability : float
        The nominal ``p``, ``0 < p ≤ 1`` (a claim with a large ``k`` stands for ``p = 2Φ(k) − 1``,
        which rounds to 1 beyond ``k ≈ 8``; its tolerance is then 0).
    z : float
        Standard deviations allowed: :data:`COVERAGE_Z` (3) for the verdicts; JCGM 102 joint-region
        checks and statistical tests pass their own.
    """
    p = coverage_probability
    if isinstance(p, bool) or not isinstance(p, (int, float)) or not 0.0 < p <= 1.0:
        raise ValueError(f"coverage_probability = {p!r}: must lie in (0, 1]")
    check_count(n, "n")
    return z * math.sqrt(p * (1.0 - p) / n)


def _judges_both_ways(n: int, probability: float, z: float) -> bool:
    """Whether a coverage of 0 could fall below ``p − tol`` and one of 1 reach ``p + tol`` over *n* trials."""
    tolerance = coverage_tolerance(n, probability, z)
    return probability - tolerance > 0.0 and probability + tolerance <= 1.0


def minimum_trials_to_judge(probability: float = 0.95, z: float = COVERAGE_Z) -> int:
    """The fewest trials over which :func:`coverage_verdict` can find a statement both under- and over-stated.

    A coverage observed over ``n`` trials lies in [0, 1]; the verdict needs it ``z`` binomial
    standard deviations from ``p`` (:func:`coverage_tolerance`), which is possible on both sides
    only once ``z·sqrt(p(1 − p)/n) ≤ min(p, 1 − p)``, i.e. ``n ≥ z²·p(1 − p)/min(p, 1 − p)²``:
    171 for ``p = 0.95``, ``z = 3`` (below that even a claim covering every trial is not
    significantly above 95 %). The bound is evaluated with the verdict's own arithmetic.

    Parameters
    ----------
    probability : float
        ``p``, ``0 < p ≤ 1`` (``p = 1``: any ``n``).
    z : float
        Binomial standard deviations of the tolerance.

    Returns
    -------
    int
    """
    coverage_tolerance(1, probability, z)  # validates p
    margin = min(probability, 1.0 - probability)
    n = max(1, math.ceil(z * z * probability * (1.0 - probability) / margin**2 - 1e-9)) if margin > 0 else 1
    while not _judges_both_ways(n, probability, z):
        n += 1
    while n > 1 and _judges_both_ways(n - 1, probability, z):
        n -= 1
    return n


def coverage_verdict(coverage: float, n: int, probability: float, claimed: float, needed: float, *,
                     z: float = COVERAGE_Z, show_understatement_factor: bool = True) -> tuple[str, float]:
    """Verdict on a stated expanded uncertainty from its coverage of the truth over *n* trials.

    ``F = claimed / needed``, ``needed`` being the half-width the Monte Carlo needs for the
    probability (the p-quantile of ``|E|``); ``tol`` = :func:`coverage_tolerance` (n, p, z). The
    verdict is

    - ``"under-stated"`` if ``coverage < p − tol``;
    - ``"over-stated ×F"`` if ``coverage ≥ p + tol`` and ``F >`` :data:`OVERSTATEMENT_FACTOR`;
    - ``"too few trials to judge (n < N)"`` otherwise when ``n`` is below
      :func:`minimum_trials_to_judge` ``N`` (171 at 95 %): with so few trials the tolerance reaches
      past 0 or 1, so one of the two findings above could never be made and "supported" would
      say nothing;
    - ``"supported"`` otherwise (it includes a statement that is conservative by at most 2×).

    Parameters
    ----------
    coverage : float
        Fraction of the *n* trials with ``|E| ≤ claimed``.
    n : int
        Trials counted.
    probability : float
        The coverage probability the statement stands for (0.95 for ``k = 2``, JCGM 100 6.3.3).
    claimed, needed : float
        The stated ``U`` and the Monte Carlo's p-quantile of ``|E|``, in one unit.
    z : float
        Binomial standard deviations of the tolerance.
    show_understatement_factor : bool
        Append ``×F`` to ``"under-stated"`` too. ``plansim validate`` does (its verdict is the
        only place its text report names the factor of a short claim); ``plansim run``'s Appendix A
        table and its ``--json`` ``verdict`` say plain ``"under-stated"`` next to a separate
        ``overstatement_factor``, which docs/appendix-a.md documents, so the comparison with
        Appendix A passes False. The rule itself is the same for both.

    Returns
    -------
    verdict : str
    factor : float
        ``F`` (``inf`` if ``needed`` is 0).
    """
    factor = claimed / needed if needed > 0 else math.inf
    tolerance = coverage_tolerance(n, probability, z)
    if coverage < probability - tolerance:
        return (f"under-stated ×{factor:.3g}" if show_understatement_factor else "under-stated"), factor
    if coverage >= probability + tolerance and factor > OVERSTATEMENT_FACTOR:
        return f"over-stated ×{factor:.3g}", factor
    needed_trials = minimum_trials_to_judge(probability, z)
    if n < needed_trials:
        return f"too few trials to judge ({n} < {needed_trials})", factor
    return "supported", factor
