"""The fit's uncertainty budget: its independent inputs and their propagation to the parameters.

The segment means of a fit carry independent inputs — the noise, the table's and fixture's per-setting errors,
the site's, the held parameters', the noise between segments — each a sensitivity column over the means with a
standard uncertainty, degrees of freedom and a kind (:class:`Sources`; V = D·diag(u²)·Dᵀ). A linear estimator
θ̂ = A·m takes them to each parameter's u and ν_eff by JCGM 100 5.1.2 and G.4.1 (:func:`propagate`), and keeps the
budget in short: the root-sum-square per kind (:class:`Method`). :func:`chi2_verdict` words a χ² against its
degrees of freedom at the two-sided :data:`CHI2_FLAG_PROBABILITY`.

One of each for :mod:`plansim.fit.joint` (the joint fit and the specification's estimators),
:mod:`plansim.fit.moves` (Kg from the moves between poses) and :mod:`plansim.fit.between` (the between-segment
comparison of repeated settings).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from plansim.uncertainty.metrology.propagation import combine

#: two-sided probability outside which a χ² (fit, or between-segment comparison) is flagged
CHI2_FLAG_PROBABILITY = 0.01


@dataclass(frozen=True)
class Method:
    """The estimates of one method (39 each, SI; NaN where not identified).

    ``contributions`` maps a kind of input (``noise``, ``table``, ``angle``, ``site``, ``held``, ``data_sheet``) to
    the (39,) root-sum-square of its contributions: the budget in short.
    """

    name: str
    estimate: np.ndarray
    u: np.ndarray
    dof: np.ndarray
    contributions: dict = field(repr=False)
    note: str = ""


def chi2_quantile(dof: int, probability: float) -> float:
    """The *probability* quantile of χ² with *dof* degrees of freedom."""
    from scipy.special import chdtri

    return float(chdtri(dof, 1.0 - probability))


def chi2_verdict(chi2: float, dof: int, next_step: str = "") -> str:
    """The verdict on χ² with *dof* degrees of freedom; *next_step*, where given, is said after a flag of residuals
    larger than predicted (where to look next)."""
    from scipy.special import chdtrc

    if dof <= 0:
        return "no degrees of freedom left: the fit is exact by construction"
    upper = float(chdtrc(dof, chi2))  # P(χ² ≥ observed)
    if upper < CHI2_FLAG_PROBABILITY / 2:
        return (f"the residuals are larger than the estimated noise and table errors predict (P = {upper:.2g}): "
                "an effect the model lacks, or noise that does not average down" + (f" ({next_step})" if next_step
                                                                                     else ""))
    if upper > 1 - CHI2_FLAG_PROBABILITY / 2:
        return f"the residuals are smaller than predicted (P = {1 - upper:.2g} of so small a χ²): the stated " \
               "uncertainties may be too large"
    return f"consistent with the estimated noise and table errors (P(χ² ≥ observed) = {upper:.2g})"


class Sources:
    """The independent inputs of the segment means: sensitivity columns (6S, n), standard uncertainties,
    degrees of freedom and kinds. Their covariance is V = D·diag(u²)·Dᵀ."""

    def __init__(self, size: int):
        self.size = size
        self.columns: list[np.ndarray] = []
        self.u: list[float] = []
        self.dof: list[float] = []
        self.kind: list[str] = []

    def add(self, column, u, dof, kind):
        self.columns.append(np.asarray(column, dtype=float))
        self.u.append(float(u))
        self.dof.append(float(dof))
        self.kind.append(kind)

    def joined(self, other: Sources) -> Sources:
        """These sources and *other*'s (the same size), as a new set."""
        out = Sources(self.size)
        for source in (self, other):
            out.columns += source.columns
            out.u += source.u
            out.dof += source.dof
            out.kind += source.kind
        return out

    def matrix(self) -> np.ndarray:
        """(6S, n) sensitivity × u."""
        return np.column_stack(self.columns) * np.asarray(self.u)[None, :] if self.columns else np.zeros((self.size, 0))

    def covariance(self, kinds=None) -> np.ndarray:
        d = self.matrix()
        if kinds is not None:
            d = d[:, [k in kinds for k in self.kind]]
        return d @ d.T


def propagate(name: str, gain: np.ndarray, sources: Sources, mask: np.ndarray, note: str = "",
              prior_gain: np.ndarray | None = None, prior_u: np.ndarray | None = None) -> Method:
    """θ̂ = gain · m (+ prior_gain · nominal): u(θ̂_k) and ν_eff by JCGM 100 5.1.2 and G.4.1 over the independent
    sources, and, with *prior_gain* (·, 39), the data sheet's prior of the joint fit
    (:func:`plansim.fit.solve.solve`), one Type B input per parameter with u = *prior_u* (39,) (the fit's
    :attr:`~plansim.fit.identify.HeldPriors.limits`; kind ``data_sheet``)."""
    contributions = gain @ sources.matrix()  # (39, n)
    dofs = np.asarray(sources.dof)
    kinds = np.asarray(sources.kind, dtype=object)
    if prior_gain is not None:
        contributions = np.hstack([contributions, prior_gain * np.asarray(prior_u)[None, :]])
        dofs = np.concatenate([dofs, np.full(len(prior_u), math.inf)])
        kinds = np.concatenate([kinds, np.full(len(prior_u), "data_sheet", dtype=object)])
    u = np.full(gain.shape[0], math.nan)
    nu = np.full(gain.shape[0], math.nan)
    for k in np.flatnonzero(mask):
        u[k], nu[k] = combine(contributions[k], dofs)
    by_kind = {}
    for kind in dict.fromkeys(kinds.tolist()):
        part = np.sqrt(np.sum(contributions[:, kinds == kind] ** 2, axis=1))
        by_kind[kind] = np.where(mask, part, math.nan)
    return Method(name, np.full(gain.shape[0], math.nan), u, nu, by_kind, note)
