"""Which candidates a recording can tell apart, their score tests, and the lack of fit — with a simulated null.

**Whitened residual.** The fit solves min ‖W·(m − D z)‖² (W the fit's whitening, D its design at the
solution, :class:`plansim.fit.FitResult`), so its whitened residual is r_w = P⊥·W·m with P⊥ = I − X X⁺,
X = W·D: the part of the data the base model cannot reach.

**Identifiability.** A candidate's whitened signature W·x_k that P⊥ leaves (nearly) nothing of is a
direction the base model already spans: the effect would alias into the parameters. The surviving
fraction ‖P⊥ W x‖/‖W x‖ is taken on the singular directions of P⊥·W·X_c; those below
:data:`ALIAS_TOLERANCE` are dropped, and a candidate with none left is *not identifiable*: it gets no
p-value and is never selected. Its ``aliased_with`` lists the parameters that would absorb it (the
regression of W·x on X, mapped to the 39 parameters through the fit's identifiability basis, each in units
of its standard uncertainty), and two candidates whose surviving subspaces coincide (every principal
angle's cosine above 1 − :data:`ALIAS_TOLERANCE`) are aliased with each other.

**Score test** (a Lagrange-multiplier test of "effect size zero" at the base fit, Rao 1948): with U_c an
orthonormal basis of the candidate's surviving directions, the score vector s_c = U_cᵀ r_w has the exact
covariance Σ_c = U_cᵀ P⊥ W V Wᵀ P⊥ U_c under the fitted noise (W weighs by the fit's working covariance,
so it is not the identity), and T_c = s_cᵀ Σ_c⁻¹ s_c is χ²(rank_c) when the noise is Gaussian. The noise
model is not iid: segment means carry bias instability that does not average down,
quantisation that the noise does not dither and the table's per-setting errors, all in the fit's
covariance V. So the p-values are not read off χ² alone: the **null is simulated** from the fitted model
— e ~ N(0, V) (V = ``fit.covariance``, every input the fit knows, the between-segment noise estimated from
the residuals included), whitened and residualised exactly as the data, r*_w = P⊥·W·e — and each
candidate's analytic p is calibrated against it. The family-wise error over the catalogue is controlled
by the single-step **min-p** adjustment of Westfall & Young (1993, Algorithm 2.5): p̃_c = P*(min_d p*_d ≤
p_c), estimated as (1 + #{b: min_d p*_{d,b} ≤ p_c})/(B + 1). Holm (1979) on the analytic p-values is the
documented fallback (``method="holm"``).

**Lack of fit** (segment level): L = ‖r_w‖² against the same simulated null, p = (1 + #{L*_b ≥ L})/(B + 1),
overall and per channel (the channel's rows of r_w).

**Attribution.** Two candidates can both be significant when their signatures alias in part (ω² and |ω|
over the rate points of one axis are both even in ω). Which one the residual is attributed to is decided by each
candidate's strongest single component: its one-degree-of-freedom score (uᵀ r_w)²/(uᵀ M u), u = z/‖z‖ — the
share of the whitened residual that one parameter of that effect explains, in units of its null spread. It is
the likelihood-ratio comparison of the two one-parameter models, and unlike a p-value over the whole candidate it
does not favour the candidate with fewer components (a six-component nonlinearity against a three-component
asymmetry).

The noise-equivalent size of a component is the size at which that component alone gives its one-degree-
of-freedom score a non-centrality of 1: sqrt(uᵀ M u)/‖z‖, z = P⊥ W x_k, u = z/‖z‖, M = P⊥ W V Wᵀ P⊥.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import chdtrc

from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETER_NAMES

#: a candidate direction is aliased with the base model (or another candidate) when less than this fraction of
#: its whitened norm survives the projection (or its principal angle's cosine exceeds 1 − this)
ALIAS_TOLERANCE = 1e-3
#: a component is not excited by the schedule when its whitened column is below this fraction of the candidate's
#: largest (a second-order path only, such as a lever arm across an accelerometer's own axis through Ka's
#: cross-couplings)
EXCITATION_TOLERANCE = 1e-2
#: default number of simulated null draws
NULL_DRAWS = 2000
METHODS = ("westfall_young", "holm")


@dataclass(frozen=True)
class CandidateScore:
    """One candidate's identifiability and score test (NaN statistics when not identifiable)."""

    effect: str
    identifiable: bool
    aliased_with: tuple[str, ...]
    separating: str
    statistic: float
    dof: int
    p_value: float
    adjusted_p_value: float
    noise_equivalent_size: np.ndarray  # (m,) SI; inf where the component is aliased
    components: tuple[str, ...]
    unit: str
    usable: np.ndarray = field(repr=False, default=None)  # (m,) bool: the components the data can estimate
    #: (m,) each usable component's own one-degree-of-freedom score statistic (NaN where not usable): the
    #: evidence for that component alone, which :func:`plansim.diagnose.procedure.diagnose` compares between
    #: candidates to attribute a residual (module docstring, "Attribution")
    component_statistic: np.ndarray = field(repr=False, default=None)

    def strongest_component(self) -> float:
        """The largest one-degree-of-freedom score statistic of the candidate's usable components (0 if none)."""
        values = np.asarray(self.component_statistic if self.component_statistic is not None else [], dtype=float)
        finite = values[np.isfinite(values)]
        return float(finite.max()) if finite.size else 0.0


@dataclass(frozen=True)
class LackOfFit:
    statistic: float
    dof: int
    p_value: float
    flagged: bool
    per_channel: dict  # channel -> (statistic, dof, p_value)


#: what would separate each effect from what it aliases with, when it is not identifiable
SEPARATING = {
    "gyro_scale_asymmetry": "rate points of both signs about each gyro axis",
    "gyro_scale_nonlinearity": "three or more rate magnitudes about each gyro axis (both signs for the cubic term)",
    "gyro_g2_sensitivity": "static poses with the specific force between the axes (tilted poses), not only along them",
    "accel_quadratic": "poses at ±1 g and at 0 g on each accelerometer (both headings do not help)",
    "bias_drift": "the same setting repeated at distant times (e.g. a pose at the start and at the end)",
    "lever_arm": "rate segments with the unit at two different radii, or turning about an axis off its centre",
}


class _Geometry:
    """The whitened geometry of a fit: W (rows), X = W D, its orthonormal basis Q and the residual r_w."""

    def __init__(self, fit):
        rows = np.asarray(fit.rows, dtype=bool)
        self.W = np.asarray(fit.whitening, dtype=float)  # (n, 6S)
        self.rows = rows
        X = self.W @ np.asarray(fit.design, dtype=float)
        if X.shape[1]:
            u, s, _ = np.linalg.svd(X, full_matrices=False)
            keep = s > 1e-10 * max(s.max(), 1e-300)
            self.Q = u[:, keep]
        else:
            self.Q = np.zeros((X.shape[0], 0))
        self.X = X
        self.r = self.project(self.W @ (fit.observed - fit.fitted).ravel())
        V = np.asarray(fit.covariance, dtype=float)
        values, vectors = np.linalg.eigh(V)
        self.V_root = vectors * np.sqrt(np.maximum(values, 0.0))  # V = V_root V_rootᵀ
        self.channel_of_row = np.tile(np.arange(6), fit.observed.shape[0])[rows]
        #: P⊥ W V^{1/2}: a whitened residual's noise is this times a standard normal vector
        self.noise_map = self.project(self.W @ self.V_root)

    def scorer(self, basis: np.ndarray) -> np.ndarray:
        """(k, n) the map from a whitened residual to a candidate's standardised score vector: Σ^{-1/2}·Uᵀ, with
        Σ = Uᵀ P⊥ W V Wᵀ P⊥ U the score's exact covariance under the fitted noise (W weighs by a working
        covariance, so P⊥ W V Wᵀ P⊥ is not the identity), directions of no variance dropped."""
        L = basis.T @ self.noise_map
        values, vectors = np.linalg.eigh(L @ L.T)
        keep = values > 1e-12 * max(values.max(), 1e-300)
        return (vectors[:, keep] / np.sqrt(values[keep])).T @ basis.T

    def project(self, y: np.ndarray) -> np.ndarray:
        """P⊥ y along the first axis."""
        return y - self.Q @ (self.Q.T @ y)

    def null_residuals(self, draws: int, seed: int) -> np.ndarray:
        """(n, B) whitened residuals of data drawn from the fitted model's noise, e ~ N(0, V)."""
        rng = np.random.default_rng(seed)
        return self.noise_map @ rng.standard_normal((self.V_root.shape[1], draws))


def _chi2_sf(statistic, dof) -> np.ndarray:
    return chdtrc(dof, np.maximum(statistic, 0.0))


def _aliases(fit, geometry: _Geometry, column: np.ndarray) -> tuple[str, ...]:
    """The parameters a whitened column would move, largest in units of their u first (those above 10 % of it)."""
    if geometry.X.shape[1] == 0:
        return ()
    beta = np.linalg.lstsq(geometry.X, column, rcond=None)[0]
    rank = fit.identifiability.basis.shape[1]
    change = fit.identifiability.basis[: len(PARAMETER_NAMES)] @ beta[:rank]
    u = np.where(np.isfinite(fit.joint.u) & (fit.joint.u > 0), fit.joint.u, np.inf)
    scaled = np.abs(change) / u
    if not np.any(scaled > 0):
        return ()
    order = np.argsort(-scaled)
    return tuple(PARAMETER_NAMES[k] for k in order[:4] if scaled[k] > 0.1 * scaled[order[0]])


def score_candidates(fit, sigs, *, alpha: float = 0.05, null_draws: int = NULL_DRAWS, seed: int = 0,
                     method: str = "westfall_young", null: np.ndarray | None = None) -> tuple[CandidateScore, ...]:
    """Identifiability and score test of every candidate signature in *sigs* against *fit* (module docstring).

    Parameters
    ----------
    fit : plansim.fit.FitResult
    sigs : sequence of plansim.diagnose.catalogue.Signature
    alpha : float
        Only used to check it (0 < alpha < 1); the adjusted p-values are returned for the caller to compare.
    null_draws : int
        B, the simulated null draws (p-values resolve to 1/(B + 1)).
    seed : int
        Seed of the null draws.
    method : {"westfall_young", "holm"}
    null : (n, B) array, optional
        Null whitened residuals already drawn (:meth:`_Geometry.null_residuals`), to share with lack_of_fit.
    """
    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r}: must be between 0 and 1")
    if method not in METHODS:
        raise ValueError(f"method = {method!r}: allowed {', '.join(METHODS)}")
    if int(null_draws) < 1:
        raise ValueError(f"null_draws = {null_draws!r}: must be >= 1")
    g = _Geometry(fit)
    bases, raw = [], []
    for sig in sigs:
        Wx = g.W @ sig.columns.reshape(-1, sig.columns.shape[-1])  # (n, m)
        Z = g.project(Wx)
        norms = np.linalg.norm(Wx, axis=0)
        surviving = np.linalg.norm(Z, axis=0)
        # a component the schedule hardly excites (its whitened column a tiny fraction of the candidate's largest,
        # e.g. an accelerometer's lever arm across its own axis, seen only through Ka's cross-couplings) counts
        # as not excited; one whose column the base model spans counts as aliased
        groups = sig.groups()
        largest = np.array([norms[groups == grp].max() for grp in groups])
        excited = norms > EXCITATION_TOLERANCE * np.maximum(largest, 1e-300)
        usable = excited & (surviving > ALIAS_TOLERANCE * np.maximum(norms, 1e-300))
        # noise-equivalent size: the size at which the component alone gives its 1-dof score a non-centrality of 1,
        # sqrt(uᵀ M u)/‖z‖ with z = P⊥ W x, u = z/‖z‖ and M = P⊥ W V Wᵀ P⊥ the score's null covariance
        spread = np.linalg.norm((Z / np.where(surviving > 0, surviving, 1.0)).T @ g.noise_map, axis=1)
        nes = np.where(usable, spread / np.where(surviving > 0, surviving, 1.0), np.inf)
        # each component alone: its 1-dof standardised score (uᵀ r_w)² / (uᵀ M u)
        along = (Z / np.where(surviving > 0, surviving, 1.0)).T @ g.r
        component = np.where(usable & (spread > 0), (along / np.where(spread > 0, spread, 1.0)) ** 2, np.nan)
        if np.any(usable):
            u, s, _ = np.linalg.svd(Z[:, usable], full_matrices=False)
            basis = u[:, s > ALIAS_TOLERANCE * np.linalg.norm(Z[:, usable], axis=0).min()]
        else:
            basis = np.zeros((Z.shape[0], 0))
        lost = excited & ~usable
        aliased = () if not np.any(lost) else _aliases(
            fit, g, Wx[:, np.flatnonzero(lost)[np.argmin((surviving / np.maximum(norms, 1e-300))[lost])]])
        bases.append(basis)
        raw.append((sig, usable, nes, aliased, component))
    # candidate against candidate: surviving subspaces that coincide
    same = [set() for _ in sigs]
    for i in range(len(sigs)):
        for j in range(i + 1, len(sigs)):
            if bases[i].shape[1] == 0 or bases[j].shape[1] == 0:
                continue
            cosines = np.linalg.svd(bases[i].T @ bases[j], compute_uv=False)
            inside_i = np.sum(cosines > 1 - ALIAS_TOLERANCE) >= bases[i].shape[1]
            inside_j = np.sum(cosines > 1 - ALIAS_TOLERANCE) >= bases[j].shape[1]
            if inside_i:
                same[i].add(sigs[j].effect)
            if inside_j:
                same[j].add(sigs[i].effect)
    identifiable = [bases[i].shape[1] > 0 and not same[i] for i in range(len(sigs))]
    statistic = np.full(len(sigs), math.nan)
    dof = np.zeros(len(sigs), dtype=int)
    p = np.full(len(sigs), math.nan)
    scorers = {}
    for i, basis in enumerate(bases):
        if identifiable[i]:
            scorers[i] = g.scorer(basis)
            statistic[i] = float(np.sum((scorers[i] @ g.r) ** 2))
            dof[i] = scorers[i].shape[0]
            p[i] = float(_chi2_sf(statistic[i], dof[i]))
    adjusted = np.full(len(sigs), math.nan)
    tested = np.flatnonzero(identifiable)
    if tested.size:
        if method == "holm":
            order = tested[np.argsort(p[tested])]
            running = 0.0
            for rank, i in enumerate(order):
                running = max(running, min(1.0, (tested.size - rank) * p[i]))
                adjusted[i] = running
        else:
            if null is None:
                null = g.null_residuals(int(null_draws), seed)
            null_p = np.stack([_chi2_sf(np.sum((scorers[i] @ null) ** 2, axis=0), dof[i]) for i in tested])
            min_p = null_p.min(axis=0)
            B = null_p.shape[1]
            for i in tested:
                adjusted[i] = (1 + np.count_nonzero(min_p <= p[i])) / (B + 1)
    out = []
    for i, (sig, usable, nes, aliased, component) in enumerate(raw):
        names = tuple(aliased) + tuple(sorted(same[i]))
        out.append(CandidateScore(sig.effect, bool(identifiable[i]), names,
                                  "" if identifiable[i] else SEPARATING.get(sig.effect, ""),
                                  float(statistic[i]), int(dof[i]), float(p[i]), float(adjusted[i]), nes,
                                  sig.components, sig.unit, usable,
                                  np.where(identifiable[i], component, np.nan)))
    return tuple(out)


def lack_of_fit(fit, *, alpha: float = 0.05, null_draws: int = NULL_DRAWS, seed: int = 0,
                null: np.ndarray | None = None) -> LackOfFit:
    """The segment-level omnibus test ‖r_w‖² against the simulated null (module docstring), and per channel."""
    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r}: must be between 0 and 1")
    g = _Geometry(fit)
    if null is None:
        null = g.null_residuals(int(null_draws), seed)
    B = null.shape[1]
    L = float(g.r @ g.r)
    L_null = np.sum(null**2, axis=0)
    p = (1 + np.count_nonzero(L_null >= L)) / (B + 1)
    dof = int(g.r.size - g.Q.shape[1])
    per_channel = {}
    for c, name in enumerate(CHANNELS):
        sel = g.channel_of_row == c
        if not np.any(sel):
            continue
        Lc = float(np.sum(g.r[sel] ** 2))
        pc = (1 + np.count_nonzero(np.sum(null[sel] ** 2, axis=0) >= Lc)) / (B + 1)
        per_channel[name] = (Lc, int(sel.sum()), float(pc))
    return LackOfFit(L, dof, float(p), bool(p < alpha), per_channel)


def null_residuals(fit, draws: int = NULL_DRAWS, seed: int = 0) -> np.ndarray:
    """(n, B) simulated null whitened residuals of *fit*, to share between score_candidates and lack_of_fit."""
    return _Geometry(fit).null_residuals(int(draws), seed)
