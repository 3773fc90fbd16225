"""JCGM 100:2008 (GUM): combined standard uncertainty, effective degrees of freedom, coverage factor.

- :func:`combine` — ``u_c = sqrt(Σ u_i²)`` of independent contributions ``u_i = |c_i| u(x_i)``
  (5.1.2, eq. (10)) and their ``ν_eff``;
- :func:`welch_satterthwaite` — ``ν_eff = u_c⁴ / Σ u_i⁴/ν_i`` (G.4.1, eq. (G.2b));
- :func:`coverage_factor` — ``k_p = t_p(ν_eff)`` (G.3.4, G.4.1 eq. (G.1e)); ``U_p = k_p·u_c`` (6.2.1);
  :func:`coverage_factors` for many at once.
"""

from __future__ import annotations

import math

import numpy as np
from scipy import special  # the quantiles themselves: scipy.stats takes 1.4 s to import

__all__ = ["DEFAULT_COVERAGE_PROBABILITY", "check_coverage_probability", "check_dof", "combine", "coverage_factor",
           "coverage_factors", "welch_satterthwaite"]

#: Coverage probability of an expanded uncertainty (JCGM 100 6.2.2; the 95 % of a k = 2 statement, 6.3.3).
DEFAULT_COVERAGE_PROBABILITY = 0.95


def check_dof(dof) -> np.ndarray:
    """Degrees of freedom as a float array; each must be > 0 (``inf`` for an exactly known type B input).

    Raises
    ------
    ValueError
        If any value is nan or ``<= 0`` (JCGM 100 G.4.2 gives ``ν = ∞`` to limits taken as exact).
    """
    dof = np.asarray(dof, dtype=float)
    if np.any(np.isnan(dof)) or np.any(dof <= 0):
        raise ValueError(f"degrees of freedom {dof.tolist()!r}: each must be > 0 (inf for an exactly known "
                         "type B input, GUM G.4.2)")
    return dof


def welch_satterthwaite(contributions, dofs) -> float:
    """Effective degrees of freedom, JCGM 100 G.4.1 eq. (G.2b).

    Parameters
    ----------
    contributions : array_like
        Uncertainty contributions ``u_i(y) = |c_i| u(x_i)`` of *independent* input quantities.
    dofs : array_like
        Their degrees of freedom ``ν_i`` (``inf`` for type B inputs known exactly, G.4.2).

    Returns
    -------
    float
        ``ν_eff = u_c⁴ / Σ u_i⁴/ν_i`` with ``u_c² = Σ u_i²``; ``inf`` if every ``ν_i`` is infinite
        or every contribution is zero.

    Raises
    ------
    ValueError
        A degree of freedom ``<= 0`` or nan, a non-finite contribution, or shapes that differ.
    """
    u = np.abs(np.asarray(contributions, dtype=float))
    dof = check_dof(dofs)
    if u.shape != dof.shape:
        raise ValueError(f"contributions shape {u.shape} and dofs shape {dof.shape} differ")
    if not np.all(np.isfinite(u)):
        raise ValueError(f"contributions {u.tolist()!r}: each must be finite")
    uc2 = float(np.sum(u**2))
    finite = np.isfinite(dof)
    denominator = float(np.sum(u[finite] ** 4 / dof[finite]))
    if uc2 == 0.0 or denominator == 0.0:
        return math.inf
    return uc2**2 / denominator


def combine(contributions, dofs) -> tuple[float, float]:
    """Combined standard uncertainty and effective degrees of freedom of independent inputs.

    Parameters
    ----------
    contributions : array_like
        ``u_i(y) = c_i u(x_i)`` (the sign does not matter).
    dofs : array_like
        ``ν_i`` of each input.

    Returns
    -------
    u_c : float
        ``sqrt(Σ u_i²)``, JCGM 100 5.1.2 eq. (10).
    nu_eff : float
        :func:`welch_satterthwaite` (G.4.1).
    """
    u = np.asarray(contributions, dtype=float)
    return float(math.sqrt(np.sum(u**2))), welch_satterthwaite(u, dofs)


def coverage_factor(dof: float, coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY) -> float:
    """``k_p = t_p(ν_eff)`` of the t-distribution, JCGM 100 G.3.4 and G.4.1 eq. (G.1e).

    Parameters
    ----------
    dof : float
        ``ν_eff`` (> 0; ``inf`` for the normal distribution). A non-integer value is used as it is,
        which is equivalent to interpolating Table G.2 (G.4.1 note 1).
    coverage_probability : float
        ``p`` (strictly between 0 and 1).

    Returns
    -------
    float
        ``k_p``; ``ν = inf`` gives the normal quantile (1.960 for 95 %).
    """
    return float(coverage_factors([dof], coverage_probability)[0])


def check_coverage_probability(coverage_probability) -> None:
    """Raise ``ValueError`` unless *coverage_probability* is a number strictly between 0 and 1."""
    if not (isinstance(coverage_probability, (int, float)) and 0.0 < coverage_probability < 1.0):
        raise ValueError(f"coverage_probability = {coverage_probability!r}: must lie strictly between 0 and 1")


def coverage_factors(dofs, coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY) -> np.ndarray:
    """:func:`coverage_factor` of every ``ν_eff`` of *dofs* (array_like), in one call of each quantile function."""
    check_coverage_probability(coverage_probability)
    dofs = check_dof(dofs)
    q = 0.5 * (1.0 + coverage_probability)
    out = np.full(dofs.shape, float(special.ndtri(q)))  # ν = ∞: the normal quantile
    finite = np.isfinite(dofs)
    out[finite] = special.stdtrit(dofs[finite], q)  # Student's t quantile
    return out
