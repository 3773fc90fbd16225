"""Which candidates a recording can tell apart, their likelihood-ratio tests, the lack of fit — with a simulated null.

**Whitened residual.** The fit solves min ‖W·(m − D z)‖² (W the fit's whitening, D its design at the
solution, :class:`plansim.fit.FitResult`), so its whitened residual is r_w = P⊥·W·m with P⊥ = I − X X⁺,
X = W·D: the part of the data the base model cannot reach.

**Identifiability.** A candidate's whitened signature W·x_k that P⊥ leaves (nearly) nothing of is a
direction the base model already spans: the effect would alias into the parameters. The surviving
fraction ‖P⊥ W x‖/‖W x‖ is taken on the singular directions of P⊥·W·X_c; those below
:data:`ALIAS_TOLERANCE` are dropped, and a candidate with none left is *not identifiable*: it gets no
p-value and is never selected. Its ``aliased_with`` lists the parameters that would absorb it (the
regression of W·x on X, mapped to the 39 parameters through the basis the fit stepped in, each in units
of its standard uncertainty), and two candidates whose surviving subspaces coincide (every principal
angle's cosine above 1 − :data:`ALIAS_TOLERANCE`) are aliased with each other. Before that, a component whose
column is below :data:`EXCITATION_TOLERANCE` of the largest in its unit group *for an ideal sensor in the same
poses* (:attr:`plansim.diagnose.catalogue.Signature.geometry`) is not excited: a property of the schedule, not of
one recording's noise or fitted cross-couplings.

**The candidates' test.** Every usable component of a candidate is a one-parameter alternative: its column in
one channel's segment means (a gyro's asymmetry, a channel's drift, an accelerometer's K2 …). Its statistic is
the **profile likelihood ratio** with that channel's between-segment noise re-estimated under the alternative
(:func:`_profile_likelihood_ratios`, the step test's machinery below). The base fit estimates the between-segment
noise from residuals that hold the effect, and takes much of a slow effect up: scored against that inflated
noise (the previous version's score test, T_c = s_cᵀ Σ_c⁻¹ s_c ~ χ²(rank) at the base fit), a g²-sensitivity
of the x gyro at 5× its noise-equivalent size was found in 2 of 8 jjf2003 recordings, and a drift at 20× in
none. On a channel whose means' noise is an undithered quantiser's (:func:`undithered_channels`: V describes
their scatter only roughly) the statistic is the efficient score (zᵀ M⁺ r_w)²/(zᵀ M⁺ z) under the fitted noise
instead. A candidate's statistic is the largest of its components'. The noise model is not iid: segment means
carry bias instability that does not average down, quantisation that the noise does not dither and the table's
per-setting errors, all in the fit's covariance V. So the p-values are not read off χ²: the **null is
simulated** from the fitted model — e ~ N(0, V) (V = ``fit.covariance``, every input the fit knows, the
between-segment noise estimated from the residuals included), whitened and residualised exactly as the data,
r*_w = P⊥·W·e — and every statistic is computed on each draw as on the data (the profile too), so each
candidate's p is its statistic's rank among the draws. The family-wise error over the catalogue is controlled
by the single-step **min-p** adjustment of Westfall & Young (1993, Algorithm 2.5): p̃_c = P*(min_d p*_d ≤ p_c),
estimated as (1 + #{b: min_d p*_{d,b} ≤ p_c})/(B + 1). Holm (1979) on analytic p-values (each component's
likelihood ratio as χ²(1), Bonferroni over the candidate's components) is the documented fallback
(``method="holm"``).

**Lack of fit** (segment level): L = ‖r_w‖² against the same simulated null, p = (1 + #{L*_b ≥ L})/(B + 1), overall
and per channel (the channel's rows of r_w); and the largest **step** in one channel's level between two segments
adjacent in time (:func:`step_columns`), max over channels and boundaries of each step column's profile likelihood
ratio with the channel's between-segment noise re-estimated under the step (:func:`_step_likelihood_ratios`),
against the max of the same over the null draws. A bias that jumps part-way through a run moves every later
segment's mean: the omnibus test barely sees it, because the slow noise between segments, estimated from the same
residuals, takes it up (a correlation time of 300 s and a σ of about half the step) — and so would a step score
measured against that noise — while a step is one abrupt change where that noise changes little from one 30 s
segment to the next. The largest **change** of one parameter in time — a step part-way through the run, or a steady
drift through it (:func:`change_columns`) — is scored alike, and so is the **odd segment**: the one segment whose
mean in one channel is most off the model (:func:`outlier_columns`, a column that moves that segment's mean alone;
its profile likelihood ratio is the leave-one-segment-out residual's, with the channel's between-segment noise
re-estimated without that segment). One segment far off — a rate the table did not hold, a pose knocked, a scale
factor that holds only at some rates — is otherwise taken up by the between-segment noise, estimated from the
residuals it is in, as noise "independent from segment to segment", and no other test sees it: a 5 % loss of the x
gyro's scale factor at ±5 °/s alone (4.4e-3 rad/s, some 290 times a segment mean's u) left the omnibus at p = 0.11
and gx's between-segment noise at 69 times its samples' prediction. The tests are held together at α by their min-p
over the same draws (each draw's p-values its ranks among the draws). The diagnosis takes the omnibus and the other
three on two fits of one recording — the omnibus under the quantisation error given the level counts, the others
under the candidates' — with null draws coupled between them (:func:`coupled_null_residuals`).

**Attribution.** Two candidates can both be significant when their signatures alias in part (ω² and |ω|
over the rate points of one axis are both even in ω). Which one the residual is attributed to is decided by each
candidate's strongest single component's statistic above — the likelihood-ratio comparison of the one-parameter
models: the true column explains the residual best, so among the columns of its channel (which share the null
model's likelihood) its statistic is the largest. (The efficient score (zᵀ M⁺ r_w)²/(zᵀ M⁺ z), z = P⊥ W x and
M = P⊥ W V Wᵀ P⊥, is the same comparison with the nuisance held at the base fit's: by Cauchy–Schwarz in the M⁺
metric the true component's is the largest.) The plain projection (uᵀ r_w)²/(uᵀ M u),
u = z/‖z‖, is not (W is a working whitening, so M is not the identity): with it an injected x asymmetry was
named a quadratic nonlinearity in 6 of 10 jjf2003 recordings at 5×, its x2 component scoring 24–30 against the
asymmetry's 21. Unlike a p-value over the whole candidate, neither favours the candidate with fewer components (a
six-component nonlinearity against a three-component asymmetry).

The noise-equivalent size of a component is the size at which that component alone gives its one-degree-
of-freedom efficient score a non-centrality of 1: sqrt(uᵀ M u)/‖z‖, z = P⊥ W x_k, u = z/‖z‖, M = P⊥ W V Wᵀ P⊥.
It holds the nuisance at the base fit's, so it flatters an effect that slow noise can mimic: a linear drift over a
jjf2003 run is found at 20× it, not at 5× or 10× — the between-segment noise, re-estimated under the alternative,
takes a ramp up nearly as well as the ramp does.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.special import chdtrc
from threadpoolctl import threadpool_limits

from plansim.fit.identify import HAND_PLACEMENT
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETER_NAMES

#: a candidate direction is aliased with the base model (or another candidate) when less than this fraction of
#: its whitened norm survives the projection (or its principal angle's cosine exceeds 1 − this)
ALIAS_TOLERANCE = 1e-3
#: a component is not excited by the schedule when its column for an ideal sensor is below this fraction of the
#: largest in its unit group (a second-order path only, such as a lever arm across an accelerometer's own axis
#: through Ka's cross-couplings)
EXCITATION_TOLERANCE = 1e-2
#: a component whose column the designed excitation (table rates, gravity) gives less than this part of, the rest
#: being the Earth rate's, counts as not excited: the fit's rule for the 39 parameters (docs/fitting.md,
#: Identifiability), for the candidates (a gyro's asymmetry in static poses, through 15 °/h, is not testable)
EARTH_ONLY_TOLERANCE = 1e-3
#: the step test leaves out a channel whose segment means' predicted variance is more than this share an undithered
#: quantiser's (jjf2003's 12-bit accelerometers: all of it). Their means sit on a few codes, V describes their
#: scatter only roughly, and a step statistic — the largest of many 1-dof scores, sensitive to one odd segment —
#: flagged 6 of 40 jjf2003 null recordings there at α/2 = 0.025, every one on an accelerometer
UNDITHERED_SHARE = 0.9
#: a candidate component whose column correlates more than this with one segment's mean in one channel, on the
#: schedule's geometry (:func:`_rests_on_one_segment`), rests on that segment alone: the schedule cannot tell the
#: effect from that one segment being off (a pose knocked, a rate the table did not hold, a turn the import took for
#: rest). The bound is the attribution's own measure (plansim.diagnose.procedure._attribution): two directions at
#: cosine ρ are told apart at 10× the noise-equivalent size with probability Φ(10·√((1 − ρ)/2)), below 0.95 above
#: it. Such a component is not usable. On jjf2003 and linear_gaussian every component's largest such cosine is at
#: most 0.874 (the x2 nonlinearity); in a six-position test the g² and K2 components are 1.000 (each is, after the
#: bias and the scale factors, the shape of one pose's offset)
ONE_SEGMENT_COSINE = 1.0 - 2.0 * (1.6448536269514722 / 10.0) ** 2
#: default number of simulated null draws
NULL_DRAWS = 2000
METHODS = ("westfall_young", "holm")


@dataclass(frozen=True)
class CandidateScore:
    """One candidate's identifiability and likelihood-ratio test (NaN statistics when not identifiable)."""

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
    #: effect -> cosine (M⁺ metric) between this candidate's strongest component and that candidate's
    cosine_with: dict = field(repr=False, default_factory=dict)
    #: (m,) each usable component's efficient score (zᵀM⁺r_w)²/(zᵀM⁺z) under the fitted noise (the nuisance not
    #: re-estimated): the statistic of the lack of fit's change of a parameter, to compare the two like with like
    component_efficient: np.ndarray = field(repr=False, default=None)

    def strongest_component(self) -> float:
        """The largest one-degree-of-freedom score statistic of the candidate's usable components (0 if none)."""
        values = np.asarray(self.component_statistic if self.component_statistic is not None else [], dtype=float)
        finite = values[np.isfinite(values)]
        return float(finite.max()) if finite.size else 0.0


@dataclass(frozen=True)
class LackOfFit:
    """The segment-level lack of fit (module docstring): ``statistic`` and ``dof`` of the omnibus ‖r_w‖²,
    ``p_value`` the family's (omnibus, step, change and odd segment, min-p), ``flagged`` p_value < α;
    ``omnibus_p_value`` and ``step`` (the largest step's statistic, p, channel, place and size) each against the
    simulated null;
    ``per_channel`` channel -> (statistic, dof, p) of the omnibus on the channel's rows."""

    statistic: float
    dof: int
    p_value: float
    flagged: bool
    per_channel: dict  # channel -> (statistic, dof, p_value)
    omnibus_p_value: float = math.nan
    step: dict | None = None
    #: the largest change of one parameter part-way through the run (:func:`change_columns`): its statistic, p,
    #: parameter, place and size (SI), or None
    change: dict | None = None
    #: "step", "change", "outlier" -> the 1 − α quantile of the family's largest statistic over the null draws: how
    #: much the best of its many columns gains on noise alone (plansim.diagnose.procedure: whether it explains the
    #: residual clearly better than a candidate)
    margins: dict = field(repr=False, default_factory=dict)
    #: the segment whose mean in one channel is most off the model (:func:`outlier_columns`): its statistic, p,
    #: channel, segment, label, time and size (SI), or None
    outlier: dict | None = None


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
        # one BLAS thread, whoever calls: where eigenvalues coincide, the eigenvectors' basis — and so every null
        # draw below — is the BLAS's, and differed with its thread count (same seed, same numbers)
        with threadpool_limits(limits=1, user_api="blas"):
            values, vectors = np.linalg.eigh(V)
        self.V_root = vectors * np.sqrt(np.maximum(values, 0.0))  # V = V_root V_rootᵀ
        self.V_basis = vectors  # V_root V_basisᵀ is V's symmetric square root (coupled_null_residuals)
        self.channel_of_row = np.tile(np.arange(6), fit.observed.shape[0])[rows]
        # W = Λ^{-1/2} Uᵀ (on the fitted rows: plansim.fit.solve.whitening) whitens along V's eigenvectors, so an
        # entry of r_w is not one segment's channel; U r_w is the residual whitened by V's symmetric root
        # U Λ^{-1/2} Uᵀ, whose entries are the fitted rows (a channel's rows exactly when V does not couple
        # channels, nearly when it does): what a statistic over one channel's rows must sum
        fitted_columns = self.W[:, rows]
        self.to_rows = (fitted_columns / np.linalg.norm(fitted_columns, axis=1)[:, None]).T
        #: P⊥ W V^{1/2}: a whitened residual's noise is this times a standard normal vector
        self.noise_map = self.project(self.W @ self.V_root)

    def spread(self, U: np.ndarray) -> np.ndarray:
        """(m,) the null standard deviation of each column u of *U*'s plain score uᵀ r_w: √(uᵀ M u),
        M = P⊥ W V Wᵀ P⊥."""
        return np.linalg.norm(U.T @ self.noise_map, axis=1)

    def _pinv(self) -> np.ndarray:
        """M⁺, M = P⊥ W V Wᵀ P⊥ (cached)."""
        if not hasattr(self, "_M_pinv"):
            M = self.noise_map @ self.noise_map.T
            values, vectors = np.linalg.eigh(M)
            keep = values > 1e-10 * max(values.max(), 1e-300)
            self._M_pinv = (vectors[:, keep] / values[keep]) @ vectors[:, keep].T
        return self._M_pinv

    def cosine(self, a: np.ndarray, b: np.ndarray) -> float:
        """aᵀM⁺b / √(aᵀM⁺a · bᵀM⁺b): the correlation of the two columns' efficient scores under the null."""
        P = self._pinv()
        denominator = math.sqrt(max(float(a @ P @ a) * float(b @ P @ b), 0.0))
        return float(a @ P @ b) / denominator if denominator > 0 else math.nan

    def efficient(self, Z: np.ndarray, y: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Each column z of *Z* (whitened, projected): the cross term zᵀM⁺y ((m,) for y (n,), (m, B) for (n, B);
        y the whitened residual by default) and the information zᵀM⁺z (m,), M = P⊥ W V Wᵀ P⊥; the efficient
        1-dof score is cross²/information (GLS in that metric: W is a working whitening, so M is not the
        identity)."""
        PZ = self._pinv() @ Z
        return PZ.T @ (self.r if y is None else y), np.sum(Z * PZ, axis=0)

    def surviving(self, columns: np.ndarray, where: list):
        """The columns (6S, K) whitened and projected, those the base model leaves more than
        :data:`ALIAS_TOLERANCE` of, and their *where*; None if none survives."""
        whitened = self.W @ columns
        Z = self.project(whitened)
        keep = np.linalg.norm(Z, axis=0) > ALIAS_TOLERANCE * np.maximum(np.linalg.norm(whitened, axis=0), 1e-300)
        if not np.any(keep):
            return None
        return Z[:, keep], [w for w, k in zip(where, keep) if k]

    def project(self, y: np.ndarray) -> np.ndarray:
        """P⊥ y along the first axis."""
        return y - self.Q @ (self.Q.T @ y)

    def null_residuals(self, draws: int, seed: int) -> np.ndarray:
        """(n, B) whitened residuals of data drawn from the fitted model's noise, e ~ N(0, V)."""
        rng = np.random.default_rng(seed)
        return self.noise_map @ rng.standard_normal((self.V_root.shape[1], draws))


def _component_statistics(fit, g: _Geometry, Z: np.ndarray, channel: np.ndarray, null: np.ndarray):
    """Each candidate component's 1-dof statistic, (K,) on the data and (K, B) on the null draws (module docstring,
    "The candidates' test"): the profile likelihood ratio with its channel's between-segment noise re-estimated under it
    (:func:`_profile_likelihood_ratios`), or, on a channel whose means' noise is an undithered quantiser's
    (:func:`undithered_channels`, where V describes the scatter only roughly and the step test is left out too),
    the efficient score (zᵀM⁺r_w)²/(zᵀM⁺z) under the fitted noise."""
    values = np.full(channel.size, np.nan)
    null_values = np.full((channel.size, null.shape[1]), np.nan)
    rough = np.isin(channel, sorted(undithered_channels(fit)))
    if np.any(~rough):
        k = np.flatnonzero(~rough)
        values[k], null_values[k], _ = _profile_likelihood_ratios(fit, g, Z[:, k], channel[k], null)
    if np.any(rough):
        k = np.flatnonzero(rough)
        cross, information = g.efficient(Z[:, k])
        information = np.where(information > 0, information, np.inf)
        values[k] = cross**2 / information
        null_values[k] = g.efficient(Z[:, k], null)[0] ** 2 / information[:, None]
    return values, null_values


def _noise_equivalent_sizes(g: _Geometry, Z: np.ndarray) -> np.ndarray:
    """(m,) each whitened, projected column z's size of non-centrality 1 (module docstring): √(uᵀ M u)/‖z‖,
    u = z/‖z‖, M = P⊥ W V Wᵀ P⊥; inf where ‖z‖ = 0."""
    norm = np.linalg.norm(Z, axis=0)
    safe = np.where(norm > 0, norm, 1.0)
    return np.where(norm > 0, g.spread(Z / safe) / safe, np.inf)


def _rests_on_one_segment(fit, g: _Geometry, ideal: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Which candidate components rest on one segment (:data:`ONE_SEGMENT_COSINE`), judged on the schedule's
    geometry as the excitation is: the ideal sensor's columns *ideal* (6S, m), each channel's rows scaled by its
    typical segment-mean standard deviation (the median of V's diagonal over its rows, so that channels in
    different units weigh alike), the base design projected out (P⊥, unweighted), against each fitted segment's
    mean in one channel projected alike: cosine |z_k| / (‖z‖·√(1 − ‖Q_k‖²)) for z = P⊥ x and Q an orthonormal basis
    of the scaled design. Not in V's metric: an undithered quantiser's covariance made one jjf2003 recording's
    K2 z rest on one segment (cosine 1.000) and another's not (0.41). Returns (m,) bool and (m,) the flat index
    s·6 + c of that segment's channel (into the fit's segments)."""
    flat = np.flatnonzero(g.rows)
    m = ideal.shape[1]
    if not flat.size or not m:
        return np.zeros(m, dtype=bool), np.zeros(m, dtype=int)
    if not hasattr(g, "_one_segment"):
        variance = np.diag(np.asarray(fit.covariance, dtype=float))
        channel = flat % 6
        scale = np.ones(flat.size)
        for c in np.unique(channel):
            scale[channel == c] = math.sqrt(max(float(np.median(variance[flat[channel == c]])), 1e-300))
        D = np.asarray(fit.design, dtype=float)[flat] / scale[:, None]
        Q = np.zeros((flat.size, 0))
        if D.shape[1]:
            u, sv, _ = np.linalg.svd(D, full_matrices=False)
            Q = u[:, sv > 1e-10 * max(sv.max(), 1e-300)]
        g._one_segment = (Q, scale, np.sqrt(np.maximum(1.0 - np.sum(Q**2, axis=1), 0.0)))
    Q, scale, left = g._one_segment
    X = ideal[flat] / scale[:, None]
    Z = X - Q @ (Q.T @ X)
    norm = np.linalg.norm(Z, axis=0)
    aliased = norm <= ALIAS_TOLERANCE * np.maximum(np.linalg.norm(X, axis=0), 1e-300)  # the base model spans it
    with np.errstate(invalid="ignore", divide="ignore"):
        # a segment's channel the base model spans (less than ALIAS_TOLERANCE of it survives) is no alternative
        cosine = np.where((left[:, None] > ALIAS_TOLERANCE) & ~aliased[None, :],
                          np.abs(Z) / (np.maximum(left[:, None], ALIAS_TOLERANCE) * np.maximum(norm[None, :], 1e-300)),
                          0.0)
    best = np.argmax(cosine, axis=0)
    return cosine[best, np.arange(m)] > ONE_SEGMENT_COSINE, flat[best]


def _chi2_sf(statistic, dof) -> np.ndarray:
    return chdtrc(dof, np.maximum(statistic, 0.0))


def _aliases(fit, geometry: _Geometry, column: np.ndarray) -> tuple[str, ...]:
    """What would absorb a whitened column: each parameter's part of the column the fit takes up, ‖W·J_k·Δ_k‖ (J_k
    its design column at the solution, Δ_k its change in the fit's own basis), and the hand placement's (every
    nuisance tilt together) as one; the largest first, those above 10 % of the largest, at most four.

    Not in units of each parameter's u: where the hand placement and parameters the recording does not identify
    take a column up (an accelerometer's K2 on poses turned by hand about one axis: Bay, Kayy and Kazz at parts of
    8·10⁵, 6·10⁵ and 3·10⁵), the identified parameters' share (gzz, gyy at 9 and 7) had been listed for it."""
    if geometry.X.shape[1] == 0:
        return ()
    beta = np.linalg.lstsq(geometry.X, column, rcond=None)[0]
    basis = fit.basis  # the fit's own combinations: the columns of X (not always fit.identifiability.basis)
    change = basis @ beta[:basis.shape[1]]  # (39 + nuisance,)
    n = len(PARAMETER_NAMES)
    W = geometry.W
    parts = np.abs(change[:n]) * np.linalg.norm(W @ fit.model.parameter_jacobian(tilts=fit.nuisance), axis=0)
    names = list(PARAMETER_NAMES)
    if change.size > n:
        tilt = W @ fit.model.tilt_jacobian(fit.theta, fit.nuisance) @ change[n:]
        parts = np.append(parts, np.linalg.norm(tilt))
        names.append(HAND_PLACEMENT)
    if not np.any(parts > 0):
        return ()
    order = np.argsort(-parts)
    return tuple(names[k] for k in order[:4] if parts[k] > 0.1 * parts[order[0]])


def score_candidates(fit, sigs, *, alpha: float = 0.05, null_draws: int = NULL_DRAWS, seed: int = 0,
                     method: str = "westfall_young", null: np.ndarray | None = None) -> tuple[CandidateScore, ...]:
    """Identifiability and likelihood-ratio test of every candidate signature in *sigs* against *fit* (module
    docstring).

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
    bases, raw, lone_of = [], [], []
    for sig in sigs:
        Wx = g.W @ sig.columns.reshape(-1, sig.columns.shape[-1])  # (n, m)
        Z = g.project(Wx)
        norms = np.linalg.norm(Wx, axis=0)
        surviving = np.linalg.norm(Z, axis=0)
        # a component the schedule hardly excites (its column a tiny fraction of the largest in its unit group, for
        # an ideal sensor in the same poses: e.g. an accelerometer's lever arm across its own axis, seen only
        # through Ka's fitted cross-couplings) counts as not excited — decided on the schedule's geometry, so the
        # same for every recording of one schedule; one whose column the base model spans counts as aliased
        groups = sig.groups()
        ideal = sig.columns if sig.geometry is None else sig.geometry
        geometry = np.linalg.norm(ideal.reshape(-1, ideal.shape[-1])[g.rows], axis=0)
        largest = np.array([geometry[groups == grp].max() for grp in groups])
        excited = geometry > EXCITATION_TOLERANCE * np.maximum(largest, 1e-300)
        if sig.designed is not None:  # reached by the Earth rate alone: true, and of no use (docs/fitting.md)
            excited &= sig.designed > EARTH_ONLY_TOLERANCE
        usable = excited & (surviving > ALIAS_TOLERANCE * np.maximum(norms, 1e-300))
        lone, lone_at = _rests_on_one_segment(fit, g, ideal.reshape(-1, ideal.shape[-1]))
        lone &= usable
        usable &= ~lone
        # noise-equivalent size: the size at which the component alone gives its 1-dof score a non-centrality of 1,
        # sqrt(uᵀ M u)/‖z‖ with z = P⊥ W x, u = z/‖z‖ and M = P⊥ W V Wᵀ P⊥ the score's null covariance
        nes = np.where(usable, _noise_equivalent_sizes(g, Z), np.inf)
        if np.any(usable):
            u, s, _ = np.linalg.svd(Z[:, usable], full_matrices=False)
            basis = u[:, s > ALIAS_TOLERANCE * np.linalg.norm(Z[:, usable], axis=0).min()]
        else:
            basis = np.zeros((Z.shape[0], 0))
        lost = excited & ~usable
        aliased = () if not np.any(lost) else _aliases(
            fit, g, Wx[:, np.flatnonzero(lost)[np.argmin((surviving / np.maximum(norms, 1e-300))[lost])]])
        if np.any(lone):  # "one segment (its label) for the components resting on it"
            resting: dict[int, list[str]] = {}
            for j in np.flatnonzero(lone):
                resting.setdefault(int(lone_at[j]) // 6, []).append(sig.components[j])
            aliased = tuple(aliased) + tuple(f"one segment ({fit.labels[s]}) for {' '.join(c)}"
                                             for s, c in resting.items())
        bases.append(basis)
        lone_of.append(lone)
        raw.append((sig, usable, nes, aliased, Z))
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
    # every usable component of an identifiable candidate alone: its 1-dof statistic on the data and on each null
    # draw (_component_statistics: a profile likelihood ratio, or the efficient score on an undithered channel)
    if null is None:
        null = g.null_residuals(int(null_draws), seed) if method == "westfall_young" else np.zeros((g.r.size, 0))
    B = null.shape[1]
    tested = np.flatnonzero(identifiable)
    owner, columns, channels = [], [], []
    for i in tested:
        sig, usable, _, _, Z = raw[i]
        for j in np.flatnonzero(usable):
            owner.append((i, j))
            columns.append(Z[:, j])
            channels.append(int(np.argmax(np.linalg.norm(sig.columns[:, :, j], axis=0))))
    component_values = {}
    null_of = {}
    if owner:
        values, null_values = _component_statistics(fit, g, np.column_stack(columns), np.array(channels), null)
        for k, (i, j) in enumerate(owner):
            component_values[(i, j)] = values[k]
            null_of.setdefault(i, []).append(null_values[k])
    statistic = np.full(len(sigs), math.nan)
    dof = np.zeros(len(sigs), dtype=int)
    p = np.full(len(sigs), math.nan)
    candidate_null = {}
    for i in tested:
        mine = [component_values[(i, j)] for j in np.flatnonzero(raw[i][1])]
        statistic[i] = float(max(mine))
        dof[i] = len(mine)
        if method == "holm":  # analytic: each component's likelihood ratio ~ χ²(1), Bonferroni over them
            p[i] = float(min(1.0, dof[i] * _chi2_sf(statistic[i], 1)))
        else:
            candidate_null[i] = np.max(null_of[i], axis=0)
            p[i] = float((1 + np.count_nonzero(candidate_null[i] >= statistic[i])) / (B + 1))
    adjusted = np.full(len(sigs), math.nan)
    if tested.size:
        if method == "holm":
            order = tested[np.argsort(p[tested])]
            running = 0.0
            for rank, i in enumerate(order):
                running = max(running, min(1.0, (tested.size - rank) * p[i]))
                adjusted[i] = running
        else:
            min_p = np.min([_draw_p_values(candidate_null[i]) for i in tested], axis=0)
            for i in tested:
                adjusted[i] = (1 + np.count_nonzero(min_p <= p[i])) / (B + 1)
    component, efficient = [], []
    directions = {}
    for i, (sig, usable, _, _, Z) in enumerate(raw):
        values = np.full(len(sig.components), np.nan)
        for j in np.flatnonzero(usable):
            values[j] = component_values.get((i, j), np.nan)
        component.append(values)
        cross, information = g.efficient(Z)
        efficient.append(np.where(usable & (information > 0) & identifiable[i],
                                  cross**2 / np.where(information > 0, information, 1.0), np.nan))
        if identifiable[i] and np.any(np.isfinite(values)):
            directions[i] = Z[:, int(np.nanargmax(values))]
    out = []
    # the cosine, in the M⁺ metric, between each pair of candidates' strongest components: how far the schedule
    # tells the two apart (procedure: the attribution's reliability)
    cosines = [{} for _ in sigs]
    for i in directions:
        for j in directions:
            if i != j:
                cosines[i][sigs[j].effect] = g.cosine(directions[i], directions[j])
    for i, (sig, usable, nes, aliased, _) in enumerate(raw):
        names = tuple(aliased) + tuple(sorted(same[i]))
        separating = "" if identifiable[i] else SEPARATING.get(sig.effect, "")
        if not identifiable[i] and np.any(lone_of[i]):
            separating = ("a second segment that excites it (it rests on one segment, which that segment alone being "
                          f"off would move alike); or {separating}")
        out.append(CandidateScore(sig.effect, bool(identifiable[i]), names, separating,
                                  float(statistic[i]), int(dof[i]), float(p[i]), float(adjusted[i]), nes,
                                  sig.components, sig.unit, usable, component[i], cosines[i], efficient[i]))
    return tuple(out)


def undithered_channels(fit) -> set[int]:
    """The channels whose segment means' predicted variance is mostly an undithered quantiser's (more than
    :data:`UNDITHERED_SHARE`): their means sit on a few codes and V describes their scatter only roughly."""
    noise = getattr(fit, "noise", None)
    if noise is None:
        return set()
    return {c for c in range(6) if np.median(noise.quantisation_variance[:, c] / np.maximum(
        noise.mean_variance[:, c], 1e-300)) > UNDITHERED_SHARE}


def step_columns(fit) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """The columns (6S, m) of a step in one channel's level between two segments adjacent in time: for channel
    c and the k-th boundary of the used segments in time order, 1 on c's fitted rows of every segment after it;
    and each column's (channel, last segment before, first segment after) (indices into the fit's segments)."""
    times = np.asarray(fit.segment_times, dtype=float)
    S = times.size
    order = np.argsort(times, kind="stable")
    rows = np.asarray(fit.fitted_rows, dtype=bool)
    columns, where = [], []
    excluded = undithered_channels(fit)
    for c in range(6):
        if c in excluded:
            continue  # its means' noise is an undithered quantiser's, which V describes only roughly
        for k in range(1, S):
            column = np.zeros((S, 6))
            column[order[k:], c] = 1.0
            column[~rows] = 0.0
            if column.any() and column[rows].sum() < rows[:, c].sum():  # a change, not the whole channel
                columns.append(column.ravel())
                where.append((c, int(order[k - 1]), int(order[k])))
    return (np.array(columns).T if columns else np.zeros((6 * S, 0))), where


def outlier_columns(fit) -> tuple[np.ndarray, list[tuple[int, int, int]]]:
    """The columns (6S, m) of one segment's mean off the model in one channel: for channel c and segment s, 1 on
    c's fitted row of s alone; and each column's (channel, segment, segment) (indices into the fit's segments).
    A channel left out of the step test (its means' noise an undithered quantiser's, :data:`UNDITHERED_SHARE`) is
    left out here too. A segment the base model needs to identify a combination (what the held-out check does not
    hold out) has a column the base model spans, and :meth:`_Geometry.surviving` drops it."""
    rows = np.asarray(fit.fitted_rows, dtype=bool)
    S = rows.shape[0]
    excluded = undithered_channels(fit)
    columns, where = [], []
    for c in range(6):
        if c in excluded:
            continue
        for s in np.flatnonzero(rows[:, c]):
            column = np.zeros((S, 6))
            column[s, c] = 1.0
            columns.append(column.ravel())
            where.append((c, int(s), int(s)))
    return (np.array(columns).T if columns else np.zeros((6 * S, 0))), where


#: the grid of σ²·λ_max over which the step test profiles a channel's between-segment noise (0: none; then
#: 10⁻² … 10⁴): the same grid for the data and every null draw, so a coarse grid costs a little power, not level
STEP_PROFILE_GRID = np.concatenate([[0.0], np.logspace(-2.0, 4.0, 25)])


def _step_likelihood_ratios(fit, g: _Geometry, columns: np.ndarray, where: list, null: np.ndarray):
    """The profile likelihood ratio of a step in one channel's level, for each step column, on the data and on
    every null draw; ``None`` if no column survives the base model. Any column that lives in one channel's rows,
    *where* giving its channel first, is scored the same way: the odd segment's too (:func:`outlier_columns`).

    A bias that jumps part-way through a run puts a step into the residuals, and the between-segment noise the
    base fit estimates from those same residuals (:func:`plansim.fit.between.between_segment_noise`: a term of
    variance σ_c² correlated as exp(−|t_s − t_r|/τ_c) between segments) takes it up: scored against that
    inflated noise a step scores almost the same whatever its size (a linear_gaussian recording's p went from
    0.020 at 10× to 0.008 at 20× and 0.004 at 40× a segment mean's u). So the nuisance is re-estimated under each
    alternative, as a likelihood-ratio test does (:func:`_profile_likelihood_ratios`).

    Returns
    -------
    (K,) statistics, (B,) the largest over columns of each null draw, (K,) each step's size at its maximum
    (SI, the GLS estimate in the channel's own unit), and the (channel, before, after) of each kept column.
    """
    kept = g.surviving(columns, where)
    if kept is None:
        return None
    WS, where = kept
    statistic, null_statistic, size = _profile_likelihood_ratios(fit, g, WS, np.array([w[0] for w in where]), null)
    return statistic, null_statistic.max(axis=0), size, where


def _profile_likelihood_ratios(fit, g: _Geometry, WS: np.ndarray, channel: np.ndarray, null: np.ndarray):
    """Each column's profile likelihood ratio with its channel's between-segment noise re-estimated under it, on
    the data and on every null draw.

    For channel c, with M₀ the whitened residual covariance without c's between term and N_c(τ) = P⊥ W Σ_c(τ) Wᵀ P⊥
    that term's shape, both diagonalised at once (T = M₀^{-1/2} on its range, T N_c T = Q Λ Qᵀ), the whitened
    residual z = Qᵀ T r and a column x = Qᵀ T P⊥ W s give

        ℓ₀(σ², τ) = −½ Σ_i [log(1 + σ²λ_i) + z_i²/(1 + σ²λ_i)],
        ℓ₁(σ², τ) = ℓ₀ + ½ (Σ w_i x_i z_i)² / Σ w_i x_i²,   w_i = 1/(1 + σ²λ_i),

    and the statistic 2·(max ℓ₁ − max ℓ₀), both maximised over τ in
    :data:`plansim.fit.between.BETWEEN_CORRELATION_TIMES` and σ² on :data:`STEP_PROFILE_GRID` — for the data and
    for each null draw alike, so the simulated null calibrates it whatever the grid. The other channels' between
    terms stay as the fit estimated them. At σ² = 0 with no between term in c it is the efficient score.

    Parameters
    ----------
    WS : (n, K) array
        The columns, whitened and projected (P⊥ W s).
    channel : (K,) int array
        The channel whose between-segment noise each column's alternative re-estimates.
    null : (n, B) array

    Returns
    -------
    (K,) statistics, (K, B) the same on each null draw, (K,) each column's size at its maximum (the GLS estimate
    of its coefficient).
    """
    from plansim.fit.between import BETWEEN_CORRELATION_TIMES, time_correlation

    times = np.asarray(fit.segment_times, dtype=float)
    fitted = np.asarray(fit.fitted_rows, dtype=bool)
    slow = fit.between_noise
    Wp = g.project(g.W)  # P⊥ W, (n, 6S)
    M = g.noise_map @ g.noise_map.T
    B = null.shape[1]
    statistic, size = np.full(channel.size, -np.inf), np.zeros(channel.size)
    null_statistic = np.full((channel.size, B), -np.inf)
    for c in np.unique(channel):
        cols = np.flatnonzero(channel == c)
        segments = np.flatnonzero(fitted[:, c])
        A = Wp[:, segments * 6 + c]  # N_c(τ) = A C(τ) Aᵀ, C(τ) the segments' correlation in time
        M0 = M
        if slow is not None and slow.variance[c] > 0:
            C = time_correlation(times[segments], float(slow.correlation_time[c]))
            M0 = M - slow.variance[c] * (A @ C @ A.T)
        values, vectors = np.linalg.eigh(0.5 * (M0 + M0.T))
        ok = values > 1e-10 * max(values.max(), 1e-300)
        T = vectors[:, ok] / np.sqrt(values[ok])
        # In the basis that diagonalises T N_c T, every direction outside N_c's range (rank ≤ the channel's
        # segments) has λ = 0 and w = 1 at every σ²: its sums are taken once (the basis's rotation leaves them
        # as they are in T's), and each grid point adds only the range's (w − 1) terms.
        z, Z, X, TA = T.T @ g.r, T.T @ null, T.T @ WS[:, cols], T.T @ A
        zz, ZZ, XX, Xz, XZ = float(z @ z), np.sum(Z**2, axis=0), np.sum(X**2, axis=0), X.T @ z, X.T @ Z
        best0, best0_null = -np.inf, np.full(B, -np.inf)
        best1, best1_null = np.full(cols.size, -np.inf), np.full((cols.size, B), -np.inf)
        best_size = np.zeros(cols.size)
        for tau in BETWEEN_CORRELATION_TIMES:
            # the range of T N_c T = (TA L)(TA L)ᵀ, C(τ) = L Lᵀ: the left singular vectors of TA L
            d, U = np.linalg.eigh(time_correlation(times[segments], tau))
            P, s, _ = np.linalg.svd(TA @ (U * np.sqrt(np.maximum(d, 0.0))), full_matrices=False)
            lam = s**2
            if lam.size == 0 or lam.max() <= 0:
                continue
            zp, Zp, Xp = P.T @ z, P.T @ Z, P.T @ X
            zp2, Zp2, Xp2 = zp**2, Zp**2, Xp**2
            for t in STEP_PROFILE_GRID:
                w = 1.0 / (1.0 + (t / lam.max()) * lam)
                dw = w - 1.0
                half_log_det = 0.5 * float(np.sum(np.log(1.0 / w)))
                l0 = -half_log_det - 0.5 * (zz + float(dw @ zp2))
                l0_null = -half_log_det - 0.5 * (ZZ + dw @ Zp2)
                information = XX + dw @ Xp2
                information = np.where(information > 0, information, np.inf)
                dX = Xp * dw[:, None]
                cross = Xz + dX.T @ zp
                l1 = l0 + 0.5 * cross**2 / information
                l1_null = l0_null[None, :] + 0.5 * (XZ + dX.T @ Zp) ** 2 / information[:, None]
                better = l1 > best1
                best_size = np.where(better, cross / information, best_size)
                best1 = np.maximum(best1, l1)
                best0 = max(best0, l0)
                best0_null = np.maximum(best0_null, l0_null)
                best1_null = np.maximum(best1_null, l1_null)
        statistic[cols] = 2.0 * (best1 - best0)
        size[cols] = best_size
        null_statistic[cols] = 2.0 * (best1_null - best0_null[None, :])
    return statistic, null_statistic, size


def _draw_p_values(null_statistic: np.ndarray) -> np.ndarray:
    """Each null draw's own p among the draws (its rank; larger statistics are rarer): (B,) from (B,)."""
    B = null_statistic.size
    return (B - np.argsort(np.argsort(null_statistic, kind="stable"), kind="stable")) / B


#: the parameters whose change in time the lack of fit looks for (the biases' changes are the step test's)
CHANGE_GROUPS = ("Kg", "G", "Ka", "P")


def change_columns(fit) -> tuple[np.ndarray, list[tuple[int, int, int, str]]]:
    """The columns (6S, m) of a change of one parameter of eq. (1)/(2) in time (:func:`parameter_change_columns`) for
    each identified parameter of :data:`CHANGE_GROUPS`. A parameter read by a channel left out of the step test (its
    means' noise an undithered quantiser's, :data:`UNDITHERED_SHARE`) is left out here too."""
    from plansim.model.parameters import PARAMETERS

    rows = np.asarray(fit.fitted_rows, dtype=bool)
    excluded = undithered_channels(fit)
    design = fit.model.parameter_jacobian(tilts=fit.nuisance).reshape(rows.shape[0], 6, -1)
    design[~rows] = 0.0
    identified = set(fit.identifiability.identified)
    chosen = [k for k, spec in enumerate(PARAMETERS) if spec.group in CHANGE_GROUPS and spec.name in identified
              and not excluded & {c for c in range(6) if np.any(design[:, c, k])}]
    return parameter_change_columns(fit, chosen, design)


def parameter_change_columns(fit, parameters, design: np.ndarray | None = None
                             ) -> tuple[np.ndarray, list[tuple[int, int, int, str]]]:
    """The columns (6S, m) of a change in time of each parameter of eq. (1)/(2) in *parameters* (indices), in two
    forms, and each column's (parameter index, segment, segment, form) (indices into the fit's segments):

    - ``"step"``: the parameter changes between two segments adjacent in time: for each boundary, the parameter's
      column of the design (at the fit's solution) on the segments after it (the segments: the last before it and
      the first after it);
    - ``"linear"``: the parameter drifts at a steady rate over the run (a temperature that rises through it): its
      column times (t_s − t̄)/(t_last − t_first) on every segment s, t_s the segment's mid-time, so that its
      coefficient is the change from the first segment to the last (the segments: the first and the last in time).
      Only with three segments or more (with two it is the step).

    A column equal to the parameter's own (no segment before the boundary reads it) is not a change and is left
    out; one the base model spans otherwise is dropped where it is scored (:meth:`_Geometry.surviving`). *design*:
    the fit's parameter Jacobian (S, 6, 39) with its rows not fitted zeroed, where the caller has it already."""
    times = np.asarray(fit.segment_times, dtype=float)
    S = times.size
    order = np.argsort(times, kind="stable")
    if design is None:
        design = fit.model.parameter_jacobian(tilts=fit.nuisance).reshape(S, 6, -1)
        design[~np.asarray(fit.fitted_rows, dtype=bool)] = 0.0
    columns, where = [], []
    for k in range(1, S):
        later = order[k:]
        for p in parameters:
            column = np.zeros((S, 6))
            column[later] = design[later, :, p]
            if np.any(column) and np.any(design[order[:k], :, p]):  # a change, not the parameter itself
                columns.append(column.ravel())
                where.append((p, int(order[k - 1]), int(order[k]), "step"))
    span = float(times[order[-1]] - times[order[0]]) if S else 0.0
    if S >= 3 and span > 0:
        ramp = (times - 0.5 * (times[order[0]] + times[order[-1]])) / span
        for p in parameters:
            column = design[:, :, p] * ramp[:, None]
            if np.any(column):
                columns.append(column.ravel())
                where.append((p, int(order[0]), int(order[-1]), "linear"))
    return (np.array(columns).T if columns else np.zeros((6 * S, 0))), where


def _change_scores(g: _Geometry, columns: np.ndarray, where: list, null: np.ndarray):
    """Each change column's efficient 1-dof score (zᵀM⁺r_w)²/(zᵀM⁺z) on the data and the largest over columns of
    each null draw's; its size (zᵀM⁺r_w)/(zᵀM⁺z) (the parameter's change, SI); None if no column survives."""
    kept = g.surviving(columns, where)
    if kept is None:
        return None
    Z, where = kept
    cross, information = g.efficient(Z)
    ok = information > 0
    Z, cross, information = Z[:, ok], cross[ok], information[ok]
    where = [w for w, k in zip(where, ok) if k]
    if not where:
        return None
    statistic = cross**2 / information
    null_max = np.max(g.efficient(Z, null)[0] ** 2 / information[:, None], axis=0)
    return statistic, null_max, cross / information, where


def _largest(fit, scores, null_scores, sizes, where, B: int, what) -> tuple[dict, np.ndarray]:
    """The largest of a family's statistics (a step, a change) against the largest of each null draw: its
    ``{statistic, p_value, …what(first of where), between, labels, at_s, size}`` and each draw's own p (its rank)."""
    best = int(np.argmax(scores))
    T = float(scores[best])
    first, before, after, *form = where[best]
    found = {"statistic": T, "p_value": float((1 + np.count_nonzero(null_scores >= T)) / (B + 1)), **what(first),
             "between": [int(fit.used[before]), int(fit.used[after])],
             "labels": [fit.labels[before], fit.labels[after]],
             "at_s": float(0.5 * (fit.segment_times[before] + fit.segment_times[after])), "size": float(sizes[best]),
             **({"form": form[0]} if form else {})}
    return found, _draw_p_values(null_scores)


def lack_of_fit(fit, *, alpha: float = 0.05, null_draws: int = NULL_DRAWS, seed: int = 0,
                null: np.ndarray | None = None, local=None) -> LackOfFit:
    """The segment-level lack of fit against the simulated null (module docstring, "Lack of fit"): the omnibus
    ‖r_w‖² (overall and per channel), the largest step in one channel's level between segments adjacent in
    time, the largest change of one parameter and the odd segment, held together at α by their min-p over the
    same null draws.

    *local*: ``(fit_local, null_local)``, another fit of the same recording's segments and its null draws coupled
    with *null* (:func:`coupled_null_residuals`), on which the step, the change and the odd segment are scored
    instead of on *fit* (default: *fit* and *null*). :func:`plansim.diagnose.procedure.diagnose` takes the omnibus
    under the noise model given the level counts and the local tests under the candidates' (module docstring of
    the procedure).
    """
    if not 0 < alpha < 1:
        raise ValueError(f"alpha = {alpha!r}: must be between 0 and 1")
    g = _Geometry(fit)
    if null is None:
        null = g.null_residuals(int(null_draws), seed)
    B = null.shape[1]
    if local is None:
        local_fit, local_null, lg = fit, null, g
    else:
        local_fit, local_null = local
        lg = _Geometry(local_fit)
        if local_null.shape != (lg.r.size, B):
            raise ValueError(f"local: null draws of shape {local_null.shape}; expected {(lg.r.size, B)} (the local "
                             f"fit's {lg.r.size} whitened rows, as many draws as null's {B})")
    L = float(g.r @ g.r)
    L_null = np.sum(null**2, axis=0)
    p_omnibus = (1 + np.count_nonzero(L_null >= L)) / (B + 1)
    dof = int(g.r.size - g.Q.shape[1])
    # the largest step: each column's profile likelihood ratio, the channel's between-segment noise re-estimated
    # with the step in the model (_step_likelihood_ratios), maximised over channels and boundaries
    columns, where = step_columns(local_fit)
    step = change = None
    # each statistic's p against the simulated null, and each null draw's own p (its rank among the draws): the
    # family's p is the min-p over the statistics, against the min-p of the same draws
    ranks = [_draw_p_values(L_null)]
    p_values = [p_omnibus]
    margins = {}
    profiled = _step_likelihood_ratios(local_fit, lg, columns, where, local_null) if columns.shape[1] else None
    if profiled is not None:
        step, rank = _largest(local_fit, *profiled, B, lambda c: {"channel": CHANNELS[c]})
        ranks.append(rank)
        p_values.append(step["p_value"])
        margins["step"] = float(np.quantile(profiled[1], 1 - alpha)) if B else math.inf
    # the largest change of one parameter part-way through the run (a scale factor, a cross-coupling, a g-term)
    columns, where = change_columns(local_fit)
    scored = _change_scores(lg, columns, where, local_null) if columns.shape[1] else None
    if scored is not None:
        change, rank = _largest(local_fit, *scored, B, lambda k: {"parameter": PARAMETER_NAMES[k]})
        ranks.append(rank)
        p_values.append(change["p_value"])
        margins["change"] = float(np.quantile(scored[1], 1 - alpha)) if B else math.inf
    # the segment most off the model in one channel: the same profile likelihood ratio as the step's, for a column
    # that moves one segment's mean alone (outlier_columns)
    columns, where = outlier_columns(local_fit)
    profiled = _step_likelihood_ratios(local_fit, lg, columns, where, local_null) if columns.shape[1] else None
    outlier = None
    if profiled is not None:
        statistic, null_statistic, _, where = profiled
        found, rank = _largest(local_fit, *profiled, B, lambda c: {"channel": CHANNELS[c]})
        segment = where[int(np.argmax(statistic))][1]
        outlier = {k: v for k, v in found.items() if k not in ("between", "labels")}
        outlier.update(segment=int(local_fit.used[segment]), label=local_fit.labels[segment],
                       at_s=float(local_fit.segment_times[segment]))
        ranks.append(rank)
        p_values.append(outlier["p_value"])
        margins["outlier"] = float(np.quantile(null_statistic, 1 - alpha)) if B else math.inf
    p = p_omnibus
    if len(p_values) > 1:
        p = (1 + np.count_nonzero(np.min(ranks, axis=0) <= min(p_values))) / (B + 1)
    per_channel = {}
    r_rows, null_rows = g.to_rows @ g.r, g.to_rows @ null  # the fitted rows' own entries (_Geometry.to_rows)
    for c, name in enumerate(CHANNELS):
        sel = g.channel_of_row == c
        if not np.any(sel):
            continue
        Lc = float(np.sum(r_rows[sel] ** 2))
        pc = (1 + np.count_nonzero(np.sum(null_rows[sel] ** 2, axis=0) >= Lc)) / (B + 1)
        per_channel[name] = (Lc, int(sel.sum()), float(pc))
    return LackOfFit(L, dof, float(p), bool(p < alpha), per_channel, float(p_omnibus), step, change, margins, outlier)


def noncentrality(fit, delta) -> float:
    """The non-centrality of a known change *delta* of the fitted segment means, in the metric of the candidates'
    noise-equivalent size (module docstring): (‖z‖ / √(uᵀ M u))², z = P⊥ W δ, u = z/‖z‖, M = P⊥ W V Wᵀ P⊥ — the
    squared signal-to-noise ratio of the score along δ's own direction, what the base model leaves of it against
    the fitted noise. A candidate's component at its noise-equivalent size has non-centrality 1, so √ of this is
    δ in multiples of a noise-equivalent size: a common scale for an effect outside the catalogue
    (:mod:`plansim.checks.diagnose_check`). 0 when the base model spans δ.

    Parameters
    ----------
    fit : JointFit
        The fit (its segments, whitening and covariance).
    delta : (S, 6) array
        The change of each fitted segment's mean, SI, in the fit's segments (``fit.used``) order; its rows the fit
        leaves out are ignored.
    """
    rows = np.asarray(fit.fitted_rows, dtype=bool)
    delta = np.array(delta, dtype=float)
    if delta.shape != rows.shape:
        raise ValueError(f"delta: shape {delta.shape}, expected {rows.shape} (the fit's segments by six channels)")
    if not np.all(np.isfinite(delta)):
        raise ValueError("delta: must be finite")
    delta[~rows] = 0.0
    g = _Geometry(fit)
    whitened = g.W @ delta.ravel()
    z = g.project(whitened)
    if np.linalg.norm(z) <= ALIAS_TOLERANCE * max(float(np.linalg.norm(whitened)), 1e-300):
        return 0.0
    size = float(_noise_equivalent_sizes(g, z[:, None])[0])
    return 1.0 / size**2 if size > 0 else math.inf


def null_residuals(fit, draws: int = NULL_DRAWS, seed: int = 0) -> np.ndarray:
    """(n, B) simulated null whitened residuals of *fit*, to share between score_candidates and lack_of_fit."""
    return _Geometry(fit).null_residuals(int(draws), seed)


def coupled_null_residuals(fits, draws: int = NULL_DRAWS, seed: int = 0) -> list[np.ndarray]:
    """(n_f, B) simulated null whitened residuals of each fit of one recording, from the same draws.

    Each fit's errors are e_f = V_f^{1/2} ξ, with V_f^{1/2} the symmetric square root of its covariance and one
    ξ ~ N(0, I) for every fit: where two fits' noise models agree, a draw is the same errors for both, so that a
    statistic taken on one fit and another on the other keep, draw by draw, the dependence they have on the data
    (:func:`lack_of_fit`'s min-p over the omnibus of one fit and the local tests of another). The symmetric root
    is what couples: it varies smoothly with V, where an eigenvector basis (:meth:`_Geometry.null_residuals`)
    need not. Each fit's draws alone are N(0, V_f), whitened and residualised as its data.
    """
    geometries = [_Geometry(fit) for fit in fits]
    sizes = {g.V_basis.shape[0] for g in geometries}
    if len(sizes) != 1:
        raise ValueError(f"fits: the segment means they model differ in number ({sorted(sizes)}); expected fits of "
                         "one recording's segments")
    xi = np.random.default_rng(seed).standard_normal((sizes.pop(), int(draws)))
    return [g.noise_map @ (g.V_basis.T @ xi) for g in geometries]
