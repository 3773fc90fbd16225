"""JCGM 102:2011: several output quantities — their correlation and their joint coverage region.

- :func:`correlation_matrix` — the correlation matrix of the outputs from the Monte Carlo values
  (JCGM 102 7.6, the covariance matrix scaled by the standard uncertainties, 3.21);
- :func:`joint_region` — the hyper-ellipsoidal coverage region of several outputs (JCGM 102 6.5,
  7.7.2) against the box of their marginal ``k = 2`` intervals that a certificate would print.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from scipy import special  # the χ² quantile itself: scipy.stats takes 1.4 s to import

from plansim.uncertainty.metrology.checks import check_probability
from plansim.uncertainty.metrology.coverage import coverage_tolerance
from plansim.uncertainty.metrology.monte_carlo import select_outputs

__all__ = ["JOINT_REGION_Z", "JointRegionCheck", "correlation_matrix", "joint_region"]

#: Binomial standard deviations below p at which the marginal intervals are called misleading.
JOINT_REGION_Z = 4.0


def correlation_matrix(values) -> np.ndarray:
    """Correlation matrix of the outputs from the Monte Carlo values (JCGM 102 7.6); 0 where an output is constant.

    Parameters
    ----------
    values : (M, n) array_like
        Monte Carlo values, M >= 2.

    Returns
    -------
    (n, n) ndarray
    """
    v = np.asarray(values, dtype=float)
    if v.ndim != 2 or v.shape[0] < 2:
        raise ValueError(f"values: shape {v.shape}; expected (M, n) with M >= 2")
    cov = np.cov(v, rowvar=False)
    s = np.sqrt(np.diag(cov))
    scale = np.where(s > 0, s, np.inf)
    r = cov / np.outer(scale, scale)
    np.fill_diagonal(r, np.where(s > 0, 1.0, 0.0))
    return r


@dataclass(frozen=True)
class JointRegionCheck:
    """The joint coverage region of several outputs against their marginal intervals (JCGM 102).

    Attributes
    ----------
    parameters : tuple of str
        The outputs considered together (e.g. the nine elements of Kg).
    trials : int
        Monte Carlo values used.
    coverage_probability : float
        ``p``.
    dimension : int
        Rank of the outputs' covariance (degrees of freedom of the χ² quantile).
    chi2_quantile : float
        ``χ²_n(p)``: ``k_p²`` of the hyper-ellipsoid of a multivariate Gaussian (JCGM 102 6.5).
    mc_k : float
        ``k_p`` from the Monte Carlo (JCGM 102 7.7): square root of the p-quantile of the
        Mahalanobis distances ``(e − ē)ᵀ V⁻¹ (e − ē)`` with the MCM mean and covariance.
    fraction_in_ellipsoid : float
        Fraction of trials inside the ellipsoid ``χ²_n(p)`` (≈ p when the outputs are Gaussian).
    marginal_k : float
        Coverage factor of the marginal intervals (2).
    fraction_all_marginal : float
        Fraction of trials with *all* outputs inside ``ē_i ± k·s_i`` at once.
    box_k : float
        The ``k`` of a box ``ē_i ± k·s_i`` that holds the fraction p of the trials jointly.
    gum_fraction_in_ellipsoid : float
        Fraction of trials whose value lies inside the GUM ellipsoid ``eᵀ V_gum⁻¹ e ≤ χ²_n(p)``
        about zero (for errors: coverage of the truth by the GUM joint region); ``nan`` if not given.
    tolerance : float
        :func:`coverage_tolerance` with ``z =`` :data:`JOINT_REGION_Z`: ``4·sqrt(p(1 − p)/trials)``.
    misleading : bool
        True if the marginal intervals jointly cover less than ``p − tolerance``.
    message : str
        The finding in words.
    """

    parameters: tuple[str, ...]
    trials: int
    coverage_probability: float
    dimension: int
    chi2_quantile: float
    mc_k: float
    fraction_in_ellipsoid: float
    marginal_k: float
    fraction_all_marginal: float
    box_k: float
    gum_fraction_in_ellipsoid: float
    tolerance: float
    misleading: bool
    message: str

    def as_dict(self) -> dict:
        """Plain dictionary (``parameters`` as a list)."""
        d = dataclasses.asdict(self)
        d["parameters"] = list(self.parameters)
        return d


def _mahalanobis(centred: np.ndarray, covariance: np.ndarray) -> tuple[np.ndarray, int]:
    """Squared Mahalanobis distances with the pseudo-inverse (rank-deficient covariance allowed)."""
    w, v = np.linalg.eigh(0.5 * (covariance + covariance.T))
    keep = w > max(w.max(), 0.0) * 1e-12
    z = centred @ v[:, keep] / np.sqrt(w[keep])
    return np.sum(z**2, axis=1), int(np.count_nonzero(keep))


def joint_region(values, selection: Sequence[str], names: Sequence[str], coverage_probability: float = 0.95,
                 gum_covariance=None, marginal_k: float = 2.0) -> JointRegionCheck:
    """Check several outputs jointly (JCGM 102 7.7, 6.5): ellipsoid versus the box of marginal intervals.

    Parameters
    ----------
    values : (M, m) array_like
        Monte Carlo values of all outputs.
    selection : sequence of str
        The outputs considered together.
    names : sequence of str
        The ``m`` outputs, in the order of the columns of *values*.
    coverage_probability : float
        ``p``.
    gum_covariance : (m, m) array_like, optional
        The GUM covariance of the outputs (JCGM 102 6.2), for the fraction inside the GUM ellipsoid
        about zero.
    marginal_k : float
        ``k`` of the marginal intervals a certificate prints (2).

    Returns
    -------
    JointRegionCheck
    """
    p = check_probability(coverage_probability)
    names = tuple(names)
    idx = select_outputs(list(selection), names, "selection")
    chosen = tuple(names[i] for i in idx)
    v = np.asarray(values, dtype=float)
    if v.ndim != 2 or v.shape[1] != len(names) or v.shape[0] < 2 * len(idx):
        raise ValueError(f"values: shape {v.shape}; expected (M, {len(names)}) with M >= {2 * len(idx)}")
    e = v[:, idx]
    mean = e.mean(axis=0)
    cov = np.cov(e, rowvar=False)
    d2, rank = _mahalanobis(e - mean, cov)
    chi2 = float(special.chdtri(rank, 1.0 - p))  # the χ² quantile p
    inside = float(np.mean(d2 <= chi2))
    s = np.sqrt(np.diag(cov))
    s_safe = np.where(s > 0, s, np.inf)
    scaled = np.max(np.abs(e - mean) / s_safe, axis=1)
    all_marginal = float(np.mean(scaled <= marginal_k))
    box_k = float(np.quantile(scaled, p))
    mc_k = float(math.sqrt(np.quantile(d2, p)))
    gum_inside = math.nan
    if gum_covariance is not None:
        g = np.asarray(gum_covariance, dtype=float)
        if g.shape != (len(names), len(names)):
            raise ValueError(f"gum_covariance: shape {g.shape}; expected ({len(names)}, {len(names)})")
        gd2, grank = _mahalanobis(e, g[np.ix_(idx, idx)])
        gum_inside = float(np.mean(gd2 <= special.chdtri(grank, 1.0 - p)))
    n = e.shape[0]
    tol = coverage_tolerance(n, p, JOINT_REGION_Z)
    misleading = all_marginal < p - tol
    if misleading:
        message = (f"marginal k = {marginal_k:g} intervals of the {len(idx)} outputs hold all of them at once in only "
                   f"{all_marginal:.1%} of the trials (not {p:.0%}); a joint {p:.0%} statement needs the "
                   f"ellipsoid (k_p = {mc_k:.3g}, JCGM 102 7.7) or a box with k = {box_k:.3g}")
    else:
        message = (f"marginal k = {marginal_k:g} intervals hold all {len(idx)} outputs at once in {all_marginal:.1%} "
                   f"of the trials")
    return JointRegionCheck(parameters=chosen, trials=n, coverage_probability=p, dimension=rank, chi2_quantile=chi2,
                            mc_k=mc_k, fraction_in_ellipsoid=inside, marginal_k=float(marginal_k),
                            fraction_all_marginal=all_marginal, box_k=box_k, gum_fraction_in_ellipsoid=gum_inside,
                            tolerance=tol, misleading=misleading, message=message)
