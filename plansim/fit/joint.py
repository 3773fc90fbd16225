"""``fit_recording``: a recording's segments to parameters, with uncertainties from the data's own noise.

Steps (docs/fitting.md):

1. **Segments.** Those whose pose and rate are known (every segment of a plansim recording; a measured
   log's table segments) enter the mean model (:mod:`plansim.fit.model`). Segments of the other kinds
   (a ``move``; a pose whose orientation is approximate or unknown; a turn whose rate was not logged)
   are listed with the reason they are not used yet.
2. **Identifiability** of the 39 parameters from the rank and null space of the design
   (:mod:`plansim.fit.identify`).
3. **Noise** from the samples: Allan deviation and within-segment scatter (:mod:`plansim.fit.noise`).
4. **Type B inputs** that act once per setting and never show in the scatter: the turntable's and
   fixture's errors (the lab's grade, or JJF 2003 Table 1), the unrecorded start angle of each turning
   segment, gravity and the Earth rate when the site is not known, and the Kg entries held at their
   nominal value where the Earth rate alone meets them.
5. **Estimates.** (a) Where the procedure is complete (``check_design`` passes), the specification's
   estimators, eq. (3)–(13), on the segment means. (b) In every case, one joint generalised least
   squares over all the used segments' means, ``scipy.optimize.least_squares`` on the residuals
   whitened by the covariance V of the means (noise plus Type B): θ̂ minimises (m − Jθ)ᵀ V⁻¹ (m − Jθ)
   over the identified combinations, the rest held at the nominal point.
6. **Uncertainty** by the GUM law of propagation (JCGM 100 5.1.2): both estimators are linear in the
   segment means, θ̂ = A·m, so the contribution of each independent input (the noise of each segment
   mean, each table error, …) to θ̂_k is A_k·(∂m/∂x)·u(x); ``combine`` adds them and gives ν_eff.
7. **Residuals** per segment and channel, χ²/dof, and where the schedule repeats a setting the
   between-segment variance component from the data beside the one the noise and the table grade predict.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np
from threadpoolctl import threadpool_limits

from plansim.config.scenario import ErrorDistribution, Turntable
from plansim.estimate.jjf2003 import check_design, reduction_matrix
from plansim.estimate.segmentation import APPROXIMATE_TILT, MAD_TO_SIGMA
from plansim.fit.between import (
    SCATTER_MORE,
    BetweenSegmentNoise,
    BetweenSegments,
    add_between_segment_noise,
    between_segment_noise,
    between_segments,
)
from plansim.fit.budget import Method, Sources, chi2_quantile, chi2_verdict, propagate
from plansim.fit.identify import (
    NULL_TOLERANCE,
    RANK_TOLERANCE,
    HeldPriors,
    Identifiability,
    data_sheet_conflict,
    describe_conflict,
    identifiability,
    reversed_axis_notes,
    weakly_determined,
)
from plansim.fit.model import MeanModel, nominal_parameters
from plansim.fit.moves import MovesNotFitted, find_transitions, fit_moves
from plansim.fit.noise import UNITS_SI, NoiseEstimate, channel_kind, estimate_noise_models, quantisation_harmonics
from plansim.fit.site import TABLE_1_TURNTABLE, Site, unknown_site_inputs
from plansim.fit.solve import solve, weak_directions, whitening
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS
from plansim.schedule.segments import TABLE_ANGLE_NOTE, TABLE_RATE_NOTE, Schedule
from plansim.units import STANDARD_GRAVITY, to_unit

METHOD_SPEC = "jjf2003"
METHOD_JOINT = "joint_wls"
#: where the segment means' χ² flags residuals larger than predicted, what tests them further
DIAGNOSE_NEXT = ("plansim diagnose tests the residuals against a simulated null that holds the noise between "
                 "segments, and names an effect where one explains them")


@dataclass(frozen=True)
class AccelShear:
    """One pair of the accelerometers' cross-couplings (Ka_ij, Ka_ji) with poses placed by hand: their symmetric
    part (Ka_ij + Ka_ji)/2, a shear of the triad (its antisymmetric part is a rotation of the triad, which the
    poses' tilts take up whole). ``determined``: the poses, spread over the sphere, let the fit estimate it (the
    combination is estimable), and ``estimate`` ± ``u`` is that estimate; otherwise (poses near the body axes) it
    is held at 0 with ``u`` its Type B standard uncertainty (a bound from the fitted tilts, or the data sheet's).
    Dimensionless."""

    first: str
    second: str
    estimate: float
    u: float
    determined: bool

    @property
    def name(self) -> str:
        return f"({self.first} + {self.second})/2"


@dataclass(frozen=True)
class FitResult:
    """Everything :func:`fit_recording` found. Arrays over the used segments unless said otherwise."""

    site: Site
    turntable_source: str
    identifiability: Identifiability
    used: tuple[int, ...]  # indices into the recording's schedule
    tilts: np.ndarray  # (n_placed, 2) fitted tilt of each hand-placed pose about East and North, rad
    placed: tuple[int, ...]  # the hand-placed poses (indices into the recording's schedule)
    hand_axes: tuple[int, ...]  # body axes turned by hand (0 x, 1 y, 2 z)
    axis_tilts: np.ndarray  # (len(hand_axes), 2) fitted misalignment of each, rad
    fitted_rows: np.ndarray  # (S, 6) False where a segment's channel is not fitted (a hand turn's accelerometers)
    unused: dict  # index -> reason
    labels: tuple[str, ...]  # of the used segments
    observed: np.ndarray  # (S, 6) segment means
    fitted: np.ndarray  # (S, 6) joint model's means at θ̂
    residual_sd: np.ndarray  # (S, 6) predicted standard deviation of each residual
    noise: NoiseEstimate
    joint: Method
    spec: Method | None
    spec_note: str
    spec_bias: np.ndarray  # (39,) E[spec] − θ at the joint estimate (site's Earth rate etc.); NaN if unknown
    chi2: float
    chi2_dof: int
    chi2_verdict: str
    between: tuple[BetweenSegments, ...]
    attrs: dict = field(default_factory=dict)
    notes: tuple[str, ...] = ()
    #: the fit's internals, for what builds on it (plansim diagnose): the model of the used segments, the
    #: solution θ̂ (39, every entry; the unidentified ones at their nominal value) and the nuisance vector, the
    #: covariance V (6S, 6S) of the observed means' errors (noise, quantisation, table, site, angle), the
    #: whitening W (n_fitted, 6S) of the fitted rows, the design D (6S, rank + extra) of the fitted
    #: combinations at the solution, the fitted rows (6S,) and each used segment's middle time (S,), s
    model: MeanModel | None = field(default=None, repr=False)
    theta: np.ndarray | None = field(default=None, repr=False)
    nuisance: np.ndarray | None = field(default=None, repr=False)
    covariance: np.ndarray | None = field(default=None, repr=False)
    whitening: np.ndarray | None = field(default=None, repr=False)
    design: np.ndarray | None = field(default=None, repr=False)
    rows: np.ndarray | None = field(default=None, repr=False)
    segment_times: np.ndarray | None = field(default=None, repr=False)
    #: the basis (39 + nuisance, rank) of the fitted combinations, the first columns of ``design``: (θ, nuisance) −
    #: their start = basis·z. Not always ``identifiability.basis``: with poses placed by hand the fit steps with
    #: the held cross-couplings' rows at zero (:func:`_held_at_nominal`), or in the basis at the fitted tilts
    basis: np.ndarray | None = field(default=None, repr=False)
    #: V without the between-segment noise estimated from the residuals (what the noise model predicts)
    covariance_predicted: np.ndarray | None = field(default=None, repr=False)
    #: the between-segment noise per channel the residuals show beyond the prediction (:func:`between_segment_noise`)
    between_noise: BetweenSegmentNoise | None = None
    #: extra unknowns fitted with θ (``fit_recording(extra=…)``): their names, estimates, u and ν
    extra: Method | None = None
    extra_names: tuple[str, ...] = ()
    #: the joint estimate's gain on the segment means, θ̂ − θ0 ≈ gain·(m − model) (39, 6S), and the independent
    #: inputs of the means (sensitivity columns, u, ν, kind): what the moves' fit carries on (:mod:`plansim.fit.moves`)
    gain: np.ndarray | None = field(default=None, repr=False)
    sources: object = field(default=None, repr=False)
    #: inputs propagated through the gain but not weighed by (the triad's shear held at 0 where poses placed by hand
    #: leave it with their tilts: ``held.accel_cross``); the moves map them as they map ``sources``, and weigh by them
    held_sources: object = field(default=None, repr=False)
    #: the gyros from the moves between poses (:func:`plansim.fit.moves.fit_moves`); None without two usable moves
    moves: object = None
    #: with poses placed by hand, the accelerometer triad's shear: the symmetric part of each pair of Ka's
    #: cross-couplings that the nominal point leaves to the tilts (:class:`AccelShear`)
    shear: tuple = ()
    #: the Type B standard uncertainties of what the fit (and the moves) hold at nominal
    held: HeldPriors = field(default_factory=HeldPriors)
    #: with the data sheet as a prior (where the data leave a direction to it, :func:`solve`): the joint
    #: estimate's gain on the prior's mean, ∂θ̂/∂nominal (39, 39), each input with u = held.limits; else None
    prior_gain: np.ndarray | None = field(default=None, repr=False)
    #: with the data sheet as a prior: group -> {statistic, dof, p_value, contradicted}, whether the data contradict
    #: that group's data-sheet entry (:func:`plansim.fit.identify.data_sheet_conflict`); empty without the prior
    data_sheet_conflict: dict = field(default_factory=dict)

    @property
    def residuals(self) -> np.ndarray:
        """(S, 6) observed − fitted, SI."""
        return self.observed - self.fitted

    @property
    def identified(self) -> tuple[str, ...]:
        """The parameters identified by the segment means (the joint fit) or by the moves between poses, in the
        order of eq. (1)/(2)."""
        found = set(self.identifiability.identified) | set(self.moves.identified if self.moves else ())
        return tuple(name for name in PARAMETER_NAMES if name in found)

    @property
    def not_identified(self) -> dict:
        """name -> why, for every parameter neither the joint fit nor the moves identify."""
        out = {}
        for name, reason in self.identifiability.not_identified.items():
            if self.moves is None:
                out[name] = reason
            elif name in self.moves.identified:
                continue
            elif name in self.moves.relative:
                out[name] = self.moves.relative[name]
            else:
                out[name] = reason
        return out

    @property
    def weakly_determined(self) -> dict:
        """name -> why, for every identified parameter whose smallest u (the joint fit's, or the moves' where they
        identify it) is beyond its group's :data:`plansim.fit.identify.UNINFORMATIVE_U` or owes more than half its
        variance to the data sheet's prior (:func:`plansim.fit.identify.weakly_determined`)."""
        joint = set(self.identifiability.identified)
        u = np.array([self.joint.u[k] if name in joint else math.inf for k, name in enumerate(PARAMETER_NAMES)])
        # the data sheet's part of that u, where the joint fit carried it as a prior (solve)
        zero = np.zeros(len(PARAMETER_NAMES))
        data_sheet = np.nan_to_num(self.joint.contributions.get("data_sheet", zero))
        if self.moves is not None:
            moved = np.array([name in set(self.moves.identified) for name in PARAMETER_NAMES])
            smaller = moved & (self.moves.method.u < u)
            u = np.where(smaller, self.moves.method.u, u)
            data_sheet = np.where(smaller, np.nan_to_num(self.moves.method.contributions.get("data_sheet", zero)),
                                  data_sheet)
        return weakly_determined(self.identified, np.where(np.isfinite(u), u, math.nan), data_sheet,
                                 self.held.limits)

    @property
    def methods(self) -> tuple[Method, ...]:
        out = (self.spec, self.joint) if self.spec is not None else (self.joint,)
        return out + ((self.moves.method,) if self.moves is not None else ())


@dataclass(frozen=True)
class _Use:
    """Which segments the fit uses and how: the model's segment for each, the rows it fits, the hand-turned axes."""

    used: list
    unused: dict
    model_segments: list
    gyro_only: list  # per used segment: only its gyro means are fitted (a turn known by its angle, a hand turn)
    hand_axes: tuple
    #: each turn fitted by its angle: (its index among the used segments, the rest it starts from, the rest it ends
    #: at, its angle in rad); a rest is numbered by the motions before it, so the turns on either side of one rest
    #: (or of none) share its number (:meth:`plansim.fit.model.MeanModel.table_sources`)
    angle_turns: tuple = ()


#: a turn fitted by its rate must hold it: its mean rate may differ from its median (the steady rate) by at most
#: 5 standard errors of the median, half the samples' smallest step (a quantiser's code) and this fraction of the
#: rate (a table's rate error, with room)
STEADY_RATE_FRACTION = 1e-4


def _unsteady(samples: np.ndarray) -> str | None:
    """Why a turn's gyro output about its axis, *samples* (n,), does not hold one rate, or None where it does.

    A spin-up or a stop inside the segment pulls the mean rate, which the fit compares with the table's, away
    from the steady rate the table held (the median): by about half the ramps' share of the segment, 1 % of the
    rate for ramps over 2 % of it, ten times what a MEMS gyro's scale factor is calibrated to. The mean may differ
    from the median by 5 standard errors of the median (1.2533·σ/√n, σ robust), half the smallest step between
    the samples' values (a quantiser's code, which moves the mean and not the median) and
    :data:`STEADY_RATE_FRACTION` of the rate."""
    x = np.asarray(samples, dtype=float)
    n = x.size
    if n < 20:
        return None
    median = float(np.median(x))
    sigma = MAD_TO_SIGMA * float(np.median(np.abs(x - median)))
    levels = np.unique(x)
    step = float(np.min(np.diff(levels))) if levels.size > 1 else 0.0
    allowed = 5.0 * 1.2533 * sigma / math.sqrt(n) + 0.5 * step + STEADY_RATE_FRACTION * abs(median)
    shift = float(np.mean(x)) - median
    if abs(shift) <= allowed:
        return None
    return (f"its rate is not steady: its mean rate is {abs(shift) / max(abs(median), 1e-300):.2%} off its median "
            f"({math.degrees(median):.5g} deg/s), more than noise and quantisation allow (a spin-up or a stop inside "
            "the segment), so it is not the table's rate; trim the segment to the steady part, or give its angle "
            "instead of its rate")


def _segment_use(schedule: Schedule, recording=None) -> _Use:
    """Which segments the fit uses, and how (:class:`_Use`); with *recording*, a turn fitted by its rate is used
    only where its samples hold one rate (:func:`_unsteady`)."""
    used, unused, model_segments, gyro_only, hand_axes, angle_turns = [], {}, [], [], set(), []
    motions = 0  # motions (turns, moves) before segment k: the number of the rest it starts from
    for k, s in enumerate(schedule.segments):
        rest, motions = motions, motions + (s.test == "move" or s.is_rotating)
        if s.test == "move":
            unused[k] = "a move between poses: no reference to fit it against"
            continue
        turning = s.is_rotating
        if not turning:
            used.append(k)  # a pose placed by hand is fitted with its tilt as a nuisance parameter
            model_segments.append(s)
            gyro_only.append(False)
            continue
        if not s.rate_known and not s.angle_known:
            unused[k] = ("a turn with neither its rate nor its angle: nothing to fit it against (give the rate the "
                         "table held, or the angle turned, in the segment table)")
            continue
        # a table's turn; about the vertical its heading is only where it started, which the fit averages over
        on_table = s.orientation == "known" and (s.heading_known or s.rate_axis[1] == s.up[1])
        if not on_table and (s.orientation == "unknown" or s.rate_axis[1] != s.up[1]):
            unused[k] = (f"a turn about a horizontal axis or from a pose not known ({s.orientation}): the specific "
                         "force turns with it along a path no recording holds; not fitted (docs/fitting.md)")
            continue
        duration = s.samples / s.sample_rate
        by_angle = not (s.rate_known and on_table) and s.angle_known
        why = None if by_angle or recording is None else \
            _unsteady(recording.segment_samples(k)[:, "xyz".index(s.rate_axis[1])])
        if why is not None:
            unused[k] = why
            continue
        rate = s.angle / duration if by_angle else s.rate  # the mean rate: ∫ω dt = angle, whatever the profile
        model_segments.append(dataclasses.replace(s, rate=rate, heading=s.heading if s.heading_known else 0.0,
                                                  orientation="known"))
        if by_angle:
            angle_turns.append((len(used), rest, rest + 1, float(s.angle)))
        used.append(k)
        gyro_only.append(by_angle or not on_table)
        if not on_table:
            hand_axes.add("xyz".index(s.rate_axis[1]))
    return _Use(used, unused, model_segments, gyro_only, tuple(sorted(hand_axes)), tuple(angle_turns))


#: harmonics of the quantiser's covariance summed over every pair of segments; beyond them only the pairs whose
#: damping e^{−2π²k²·Var(δ_s − δ_r)/q²} is still above e^{−DAMPED_EXPONENT} (the diagonal, segments at one level)
FULL_HARMONICS = 64
DAMPED_EXPONENT = 40.0


def quantiser_covariance(b: np.ndarray, difference: np.ndarray, var_diff: np.ndarray, step: float) -> np.ndarray:
    """Σ_k ½·b_k,s·b_k,r·cos(2πk(μ̂_s − μ̂_r)/q)·exp(−2π²k²·Var(δ_s − δ_r)/q²), (S, S): the covariance of the
    errors of segment means through a quantiser the noise does not dither (:func:`_build_sources`).

    *b* (K, S) the harmonics' amplitudes (:func:`plansim.fit.noise.quantisation_harmonics`), *difference* and
    *var_diff* (S, S) the fitted levels' differences and their variances, *step* q. The first
    :data:`FULL_HARMONICS` are summed over every pair; the rest, whose damping has put every pair with a level
    difference known to better than a small fraction of a step below e^{−DAMPED_EXPONENT}, only over the pairs
    where it has not (the diagonal always): the same sum to ~1e-17 of its size, without K·S² work (K is 2000 for
    a segment whose samples never leave their level: b_k ~ q/πk decays slowly)."""
    K, S = b.shape
    scale = 2.0 * math.pi**2 / step**2
    cov = np.zeros((S, S))
    for k in range(1, min(K, FULL_HARMONICS) + 1):
        cov += 0.5 * np.outer(b[k - 1], b[k - 1]) * np.cos(2.0 * math.pi * k * difference / step) * np.exp(
            -scale * k**2 * var_diff)
    if K > FULL_HARMONICS:
        tail = np.arange(FULL_HARMONICS + 1, K + 1)
        rows, cols = np.nonzero(scale * (FULL_HARMONICS + 1) ** 2 * var_diff < DAMPED_EXPONENT)
        live = np.any(b[FULL_HARMONICS:] > 0, axis=0)
        keep = live[rows] & live[cols]
        rows, cols = rows[keep], cols[keep]
        if rows.size:
            terms = (0.5 * b[FULL_HARMONICS:, rows] * b[FULL_HARMONICS:, cols]
                     * np.cos(2.0 * math.pi * tail[:, None] * difference[rows, cols][None, :] / step)
                     * np.exp(-scale * tail[:, None] ** 2 * var_diff[rows, cols][None, :]))
            cov[rows, cols] += terms.sum(axis=0)
    return cov


def _prior_covariance(V: np.ndarray, sources: Sources, noise: NoiseEstimate, fitted: np.ndarray,
                      jacobian: np.ndarray) -> np.ndarray:
    """V with its quantisation part a priori: the covariance from which the uncertainty of the fitted levels is
    taken, for the damping of the quantiser's correlation (:func:`quantiser_covariance`).

    The damping stands for the uncertainty of a difference of two levels, taken as independent of the quantisation
    errors themselves. Propagated through V, it is not: V's quantisation part is built on the fitted levels, and
    where two levels fall in one code it states their errors shared, the level difference precise, and so less
    damping, in a loop that shrinks both (over 20 `jjf2003` recordings with offsets spread over steps, the
    accelerometers' cross-couplings and P came out with r.m.s. z 1.54 on their quantisation error alone; 1.11
    with the true levels). Here each distinct level's quantisation error is independent, with its mean square over
    a level unknown within its step (:attr:`~plansim.fit.noise.NoiseEstimate.quantisation_prior_variance`), and
    shared by the segments that read that level (the same fitted level as the same function of the parameters):
    r.m.s. z 1.27 on the same recordings (docs/fitting.md, tests/test_fit.py -k a_priori). Without the prior
    variance (a NoiseEstimate built elsewhere): V itself."""
    prior = noise.quantisation_prior_variance
    if prior is None or not np.any(noise.quantisation_variance > 0):
        return V
    S = fitted.shape[0]
    rows = jacobian.reshape(S, 6, -1)
    matrix = V - sources.covariance(kinds=("quantisation",))
    for c, channel in enumerate(noise.channels):
        q = channel.quantisation_step
        if not q > 0 or not np.any(noise.quantisation_variance[:, c] > 0):
            continue
        groups: list[list[int]] = []
        for k in range(S):
            for group in groups:
                r = group[0]
                if abs(fitted[k, c] - fitted[r, c]) <= 1e-9 * q and np.allclose(rows[k, c], rows[r, c], rtol=1e-9,
                                                                                  atol=0.0):
                    group.append(k)
                    break
            else:
                groups.append([k])
        for group in groups:
            idx = np.asarray(group) * 6 + c
            matrix[np.ix_(idx, idx)] += float(np.mean(prior[group, c]))
    return matrix


def _build_sources(model: MeanModel, theta: np.ndarray, noise: NoiseEstimate, turntable, site_inputs,
                   held: list[int], jacobian: np.ndarray, levels, tilts, priors: HeldPriors,
                   turn_angles: tuple = ((), 0.0)) -> Sources:
    """The inputs that act on the segment means (docs/fitting.md, "Uncertainty"). *turn_angles* = (turns, u): the
    turns fitted by an angle the table set or measured (:attr:`_Use.angle_turns`) and its angle's standard
    uncertainty at each rest (0: none); those turns then carry no rate error of the point."""
    S = model.n_segments
    sources = Sources(6 * S)
    quantisation = noise.quantisation_variance
    variance = (noise.mean_variance - quantisation).ravel()
    dof = noise.mean_variance_dof.ravel()
    for i in range(6 * S):
        column = np.zeros(6 * S)
        column[i] = 1.0
        sources.add(column, math.sqrt(max(variance[i], 0.0)), dof[i], "noise")
    # a quantiser the noise does not dither: the error of a segment mean is a function of its level μ_s,
    # e_s = Σ_k (−1)^k b_k sin(2πk(μ_s + v)/q) with the channel's offset v unknown (uniform over a step), so
    # segments at nearly the same level (a repeated setting; the rate test's accelerometers) share it:
    # Cov(e_s, e_r) = Σ_k b_k,s b_k,r/2 · cos(2πk(μ̂_s − μ̂_r)/q) · exp(−2π²k²·Var(δ_s − δ_r)/q²), δ the
    # error of the fitted level μ̂: what matters is how well the *difference* of two levels is known, not
    # each level (an unknown bias moves both alike and leaves their errors shared) (docs/fitting.md).
    # Without levels (the first pass) each segment's error is taken independent.
    for c, channel in enumerate(noise.channels):
        q = channel.quantisation_step
        if q <= 0 or not np.any(quantisation[:, c] > 0):
            continue
        if levels is None:
            for k in np.flatnonzero(quantisation[:, c] > 0):
                column = np.zeros((S, 6))
                column[k, c] = 1.0
                sources.add(column.ravel(), math.sqrt(quantisation[k, c]), math.inf, "quantisation")
            continue
        mu, level_cov = levels
        b = quantisation_harmonics(q, noise.quantisation_sigma[:, c])  # (K, S)
        b[:, quantisation[:, c] <= 0] = 0.0
        idx = np.arange(S) * 6 + c
        block = level_cov[np.ix_(idx, idx)]
        var_diff = np.maximum(np.diag(block)[:, None] + np.diag(block)[None, :] - 2.0 * block, 0.0)  # Var(δ_s − δ_r)
        difference = mu[:, c][:, None] - mu[:, c][None, :]
        cov = quantiser_covariance(b, difference, var_diff, q)
        values, vectors = np.linalg.eigh(cov)
        for value, vector in zip(values, vectors.T):
            if value > 1e-12 * values.max():
                column = np.zeros((S, 6))
                column[:, c] = vector
                sources.add(column.ravel(), math.sqrt(value), math.inf, "quantisation")
    inputs = list(model.table_sources(theta, turntable, tilts, turn_angles))
    if site_inputs is not None:
        inputs += model.site_sources(theta, *site_inputs, tilts=tilts)
    covariance = model.angle_covariance(theta, tilts)  # the start angle itself, then its interaction with each input
    for source in inputs:
        sources.add(source.sensitivity, source.u, math.inf, source.kind)
        if source.angle_spread is not None:
            covariance = covariance + source.u**2 * source.angle_spread
    # each channel's share on its own: across the channels of a segment the angle's effect is a turning vector
    # seen through Kg, whose cross terms are what is being estimated, so the fit must not lean on that
    # correlation (it would weigh a gyro's ±2e-8 rad/s on-axis leak of the Earth rate as an exact measure
    # of the ±3e-5 rad/s off-axis one)
    for s in np.flatnonzero(model.rotating | model.heading_unknown):
        for c in range(6):
            if covariance[s, c, c] > 0:
                column = np.zeros((S, 6))
                column[s, c] = 1.0
                sources.add(column.ravel(), math.sqrt(covariance[s, c, c]), math.inf, "angle")
    for k in held:
        sources.add(jacobian[:, k], priors.gyro, math.inf, "held")
    return sources


#: poses said to be set by a table are questioned where an accelerometer scatters between repeats of one up-axis
#: significantly (the repeated settings' verdict) and by at least this many times the predicted standard deviation:
#: under the prediction a variance ratio of 9 on 7 degrees of freedom has a tail probability of 4e-11, and the
#: verdict alone (0.5 % per channel) fired on 1 of 8 honest simulated table logs at 1.7 times; poses placed by hand
#: near the axes scattered 21 times (the Ferraris session, imported with --poses table)
TABLE_POSES_SCATTER = 3.0


def _table_poses_note(schedule: Schedule, between) -> list[str]:
    """A note where poses said to be set by a table whose heading was not logged (``plansim import --poses table``)
    scatter, on the accelerometers, between repeats of one up-axis more than the table's grade predicts (the
    repeated settings' verdict, :func:`plansim.fit.between.between_segments`): they may have been placed by hand."""
    if not any(s.test == "static" and s.orientation == "known" and not s.heading_known for s in schedule.segments):
        return []
    off = [b for b in between if b.channel in ("ax", "ay", "az") and b.verdict == SCATTER_MORE
           and b.observed_sd >= TABLE_POSES_SCATTER * b.predicted_sd]
    if not off:
        return []
    shown = ", ".join(f"{b.channel} by {math.degrees(b.observed_sd / STANDARD_GRAVITY):.2g} deg as a tilt "
                      f"({b.observed_sd / b.predicted_sd:.2g} times the prediction)" for b in off)
    return [f"the poses taken as set by a table, their heading not logged (plansim import --poses table), scatter "
            f"between repeats of one up-axis more than the table's grade predicts: {shown}. Were they placed by hand? "
            "Then re-import without --poses table (each pose's tilt is then fitted); or give the table's own grade "
            "(--scenario)"]


def _held_cross_couplings(ident: Identifiability, J: np.ndarray) -> list[tuple[int, int]]:
    """The pairs (Ka_ij, Ka_ji) whose symmetric part — both moved alike, a shear of the accelerometer triad — the
    recording's poses placed by hand do not determine (its direction, over the 39 parameters and the tilts, is not
    in the design's row space at the nominal point: :class:`plansim.fit.identify.Identifiability`) but that still
    moves the means (*J*). The antisymmetric part is a rotation of the triad, which the poses' tilts take up
    whole: a frame, not an error (the moves report Kg's cross-couplings relative to the triad)."""
    out = []
    for a, b in ((f"Ka{x}{y}", f"Ka{y}{x}") for x, y in ("xy", "xz", "yz")):
        i, j = PARAMETER_INDEX[a], PARAMETER_INDEX[b]
        if a in ident.identified and b in ident.identified:
            continue
        direction = np.zeros(ident.scale.size)
        direction[[i, j]] = 1.0
        if not np.any(J[:, i] + J[:, j]):
            continue
        if ident.outside_row_space(direction * ident.scale) > NULL_TOLERANCE:
            out.append((i, j))
    return out


def _accel_shear(ident: Identifiability, mask, theta, gain, sources: Sources, held: list, bound: list, J,
                 prior=None) -> tuple[AccelShear, ...]:
    """The accelerometer triad's shear with poses placed by hand (:class:`AccelShear`): for each pair of Ka's
    cross-couplings neither of which the recording identifies, its symmetric part (Ka_ij + Ka_ji)/2. Where that
    combination is estimable (in the row space of the design, as poses spread over the sphere make it: a tilt
    and a shear move the means alike only at axis-aligned poses) it is θ̂'s, with u propagated through the gain
    from the inputs (and the data sheet's prior, *prior* = (gain on it, u)), the Type B that holds the other
    pairs included but not its own; otherwise it is held at 0 with its Type B u (*bound*, the pairs *held*)."""
    held_u = {pair: u for pair, u in zip(held, bound)}
    out = []
    for x, y in ("xy", "xz", "yz"):
        a, b = PARAMETER_INDEX[f"Ka{x}{y}"], PARAMETER_INDEX[f"Ka{y}{x}"]
        if mask[a] or mask[b]:
            continue
        c = np.zeros(ident.scale.size)
        c[[a, b]] = 0.5
        scaled = np.divide(c, ident.scale, out=np.zeros_like(c), where=ident.scale > 0)
        estimable = bool(np.all(ident.scale[[a, b]] > 0)) and ident.outside_row_space(scaled) <= NULL_TOLERANCE
        if estimable:
            others = Sources(sources.size)
            for pair, u in held_u.items():
                if pair != (a, b):
                    others.add(J[:, pair[0]] + J[:, pair[1]], u, math.inf, "held")
            row = (c[:len(PARAMETER_NAMES)] @ gain)[None, :]
            prior_gain, prior_u = (None, None) if prior is None else \
                ((c[:len(PARAMETER_NAMES)] @ prior[0])[None, :], prior[1])
            u = propagate("shear", row, sources.joined(others), np.array([True]), prior_gain=prior_gain,
                          prior_u=prior_u).u[0]
            out.append(AccelShear(PARAMETER_NAMES[a], PARAMETER_NAMES[b], 0.5 * float(theta[a] + theta[b]),
                                  float(u), True))
        elif (a, b) in held_u:
            out.append(AccelShear(PARAMETER_NAMES[a], PARAMETER_NAMES[b], 0.0, float(held_u[(a, b)]), False))
    return tuple(out)


def _held_bound(model: MeanModel, theta, tilts, rows, W, nominal_rank: int, rank: int,
                pairs: list[tuple[int, int]], prior: float) -> list[float]:
    """The standard uncertainty of each held pair's symmetric part (:func:`_held_cross_couplings`): *prior*
    (:attr:`HeldPriors.accel_cross`), or less where the poses' tilts give the data a hold on it.

    At the fitted tilts, second-order terms can determine what the nominal point could not, and the fit frees
    those combinations when χ² drops by more than its 99 % quantile. Where it did not, a pair's symmetric part
    is below about √χ²₀.₉₉ times the u it would have had freed (from the design at the fitted tilts, under the
    fit's weights): uniform within that bound, its standard uncertainty is the bound/√3, if that is below the
    data sheet's. Where the fit freed them (*rank* above *nominal_rank*), the gain carries them and the bound is
    that u."""
    local = _identifiability_at(model, theta, tilts, rows)
    out = [prior] * len(pairs)
    if local.rank <= nominal_rank:
        return out
    design = np.hstack([model.parameter_jacobian(earth_rate=True, tilts=tilts),
                        model.tilt_jacobian(theta, tilts)]) @ local.basis
    X = W @ design
    information = X.T @ X
    covariance = local.basis @ np.linalg.pinv(information) @ local.basis.T
    factor = 1.0 if rank > nominal_rank else math.sqrt(chi2_quantile(local.rank - nominal_rank, 0.99) / 3.0)
    for k, (a, b) in enumerate(pairs):
        v = np.zeros(covariance.shape[0])
        v[[a, b]] = 0.5  # the symmetric part (Ka_ij + Ka_ji)/2
        freed = math.sqrt(max(float(v @ covariance @ v), 0.0))
        out[k] = min(prior, factor * freed)
    return out


def _held_at_nominal(basis: np.ndarray, held: list[int], rank: int, design: np.ndarray) -> np.ndarray:
    """The basis of the fit's steps with the *held* parameters' rows zero, where that spans what *basis* spans.

    At the nominal point a hand-placed pose's tilt and an accelerometer's cross-coupling move the means alike, so
    the determined combinations mix the two, and a step along them moves both. The combination the data cannot
    determine then stays wherever the start put it: the start's tilts, which are read from the data themselves.
    The fit's answer, and its gain on the means, would depend on that start (a cross-coupling of 0.005 moved Ba by
    twice what the gain said). Held at its nominal value (0) instead, the parameter is what the fit says it is,
    the tilts carry the combination, and the gain is the fit's derivative; the parameter's own Type B uncertainty
    (``HeldPriors.accel_cross``) goes through that gain. Returns *basis* unchanged where the zeroed one loses rank on
    *design* (the design at the nominal point, with the tilts' columns)."""
    if not held:
        return basis
    fixed = basis.copy()
    fixed[held] = 0.0
    u, sv, _ = np.linalg.svd(fixed, full_matrices=False)
    keep = sv > RANK_TOLERANCE * max(sv.max(initial=0.0), 1e-300)
    if int(keep.sum()) != rank:
        return basis
    candidate = u[:, keep] * sv[keep]
    steps = design @ candidate
    norms = np.linalg.norm(steps, axis=0)
    if np.any(norms <= 0):
        return basis
    singular = np.linalg.svd(steps / norms, compute_uv=False)
    if int(np.sum(singular > RANK_TOLERANCE * singular.max())) != rank:
        return basis
    return candidate


def _step_without_prior(W: np.ndarray, design: np.ndarray) -> np.ndarray:
    """(W·D)⁺·W: the gain of one Gauss–Newton step of the unknowns z on the means' residual without the data sheet's
    prior rows (the whitening *W*, the design *D* of z), the data-alone step of :func:`fit_recording`'s noise between
    segments and of :func:`_data_alone`."""
    return np.linalg.pinv(W @ design, rcond=RANK_TOLERANCE) @ W


def _data_alone(theta: np.ndarray, basis: np.ndarray, design: np.ndarray, W: np.ndarray, residual: np.ndarray,
                sources: Sources, mask: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """What the data alone say of the parameters, where the fit carried the data sheet as a prior: θ̂ + B·(W·D)⁺·W·r,
    one Gauss–Newton step without the prior's rows from the solution θ̂ (the fit's own design D of the identified
    combinations z, their basis B, the whitening W and the residual r = m − model(θ̂); exact where the model is
    linear, and the same step that estimates the noise between segments), and its u through that gain by
    JCGM 100 5.1.2 over the fit's *sources* (no data-sheet part). NaN where *mask* is False. Where the data sheet
    holds, it differs from θ̂ by (u/U)² of θ̂'s distance from nominal; where the data contradict it
    (:func:`plansim.fit.identify.data_sheet_conflict`), it is what the data put the unit at."""
    gain = basis[:len(theta)] @ _step_without_prior(W, design)[:basis.shape[1]]
    u = propagate("data_alone", gain, sources, mask).u
    return np.where(mask, theta + gain @ residual, math.nan), u


#: a hand-placed pose's fitted tilt component (its biases taken out) beyond this many times the Type B u of the
#: accelerometers' shear the fit holds (HeldPriors.accel_cross; 5 × 0.01 rad = 2.9° by default) is a tilt: no
#: cross-coupling the prior allows could stand in for it
TILT_BEYOND_SHEAR = 5.0


def _identifiability_at(model: MeanModel, theta: np.ndarray, tilts: np.ndarray, rows: np.ndarray) -> Identifiability:
    """What the fitted *rows* of the segment means identify with the hand-placed poses at *tilts* (the design at
    *θ*, the Earth rate left out; the tilts as nuisance parameters)."""
    return identifiability(model.parameter_jacobian(earth_rate=False, tilts=tilts)[rows],
                           nuisance=model.tilt_jacobian(theta, tilts, earth_rate=False)[rows])


def _far_tilts(tilts: np.ndarray, n_placed: int, beyond: float = APPROXIMATE_TILT) -> np.ndarray:
    """*tilts* (the nuisance parameters: two per hand-placed pose, about East and North, then two per hand-turned
    axis) with each pose's components of at most *beyond* (default
    :data:`plansim.estimate.segmentation.APPROXIMATE_TILT`) zeroed, and the hand-turned axes' zeroed: the point where
    the fit decides what a recording identifies.

    At a pose near an axis, a tilt and an accelerometer's cross-coupling move the means alike to first order, and
    the pose is taken as named, so that a fraction of a degree does not count as determining the cross-coupling
    (nor a g-sensitivity whose axis that fraction tips towards gravity). A pose turned 20–40° from its named axis
    about East or North is that far from it: gravity along it reaches the accelerometers' scale factors and biases
    of the other axes at first order, and the pose is taken where the data put it, in that component (an
    independent simulator's hand turns about x to 20°, 27° and 40° had left Kazz and Baz as "not excited", and the
    fit stuck at χ²/dof = 134 with 1.8·10³ µg on az)."""
    out = np.zeros_like(tilts)
    placed = np.asarray(tilts[:2 * n_placed], dtype=float)
    out[:2 * n_placed] = np.where(np.abs(placed) > beyond, placed, 0.0)
    return out


def _noise_segments(schedule) -> list[int]:
    """The segments whose samples show the sensors' noise: every one that is not a move."""
    return [k for k, s in enumerate(schedule.segments) if s.test != "move"]


def recording_noise(recording, stated_white=None, stated_step=None, noisier: bool = True,
                    conditional: bool = True) -> NoiseEstimate:
    """The noise of a recording's samples (:func:`plansim.fit.noise.estimate_noise` over every segment that is
    not a move, *noisier* and *conditional* passed on), which :func:`fit_recording` takes as its ``noise`` so that
    refits of the same samples share it."""
    return recording_noise_models(recording, stated_white, stated_step, noisier, (conditional,))[0]


def recording_noise_models(recording, stated_white=None, stated_step=None, noisier: bool = True,
                           conditionals=(True, False)) -> tuple[NoiseEstimate, ...]:
    """:func:`recording_noise` under each static quantisation model in *conditionals*, from one pass over the
    samples (:func:`plansim.fit.noise.estimate_noise_models`)."""
    schedule = recording.schedule
    segments = _noise_segments(schedule)
    return estimate_noise_models([np.asarray(recording.segment_samples(k), dtype=float) for k in segments],
                                 [schedule.segments[k] for k in segments], stated_white, stated_step, noisier,
                                 conditionals)


def _refuse_constant_channels(recording) -> None:
    """A ``ValueError`` naming each channel that reads one value in every sample of the recording.

    A sensor's output changes between poses at rest (gravity, the Earth rate, its noise) and in every turn: a
    channel that never does is dead, disconnected or a wrong column, and its zero scatter would weigh its segment
    means as exact (a singular fit)."""
    samples = np.asarray(recording.samples, dtype=float)
    if samples.shape[0] < 2:
        return
    constant = [c for c in range(6) if np.ptp(samples[:, c]) == 0]
    if constant:
        raise ValueError("recording: " + "; ".join(
            f"channel {CHANNELS[c]} reads {samples[0, c]:.6g} {UNITS_SI[channel_kind(c)]['mean']} in every one of its "
            f"{samples.shape[0]} samples" for c in constant)
            + ": a dead or disconnected sensor, or a wrong column (plansim import --columns); a channel that never "
              "changes cannot be fitted")


@threadpool_limits.wrap(limits=1, user_api="blas")  # small matrices: BLAS threads only compete (diagnose)
def fit_recording(recording, site: Site | None = None, turntable=None, turntable_source: str = "",
                  reference_gravity: float | None = None, omega_squared_sign: str = "model",
                  lever_arm=None, extra: dict | None = None,
                  between_noise: BetweenSegmentNoise | None = None, stated_white=None,
                  noise: NoiseEstimate | None = None, stated_step=None, moves: bool = True,
                  held: HeldPriors | None = None, progress=None, _judged: np.ndarray | None = None) -> FitResult:
    """Fit a recording: identifiability, the specification's estimators, the joint fit, noise, uncertainty.

    Parameters
    ----------
    recording : plansim.io.recording.Recording
        (or anything with ``samples`` (M, 6), ``schedule``, ``first_sample``, ``segment_means()`` and ``attrs``).
    site : Site, optional
        Where the unit was (:func:`plansim.fit.site.resolve_site`); default: not known.
    turntable : plansim.config.scenario.Turntable, optional
        The turntable's and fixture's grade; default JJF 2003 Table 1 (:data:`TABLE_1_TURNTABLE`).
    turntable_source : str
        How to name it in the report.
    reference_gravity : float, optional
        "1 g" of the specification's matrix A, m/s²; default: the site's gravity (the middle of the range
        of :func:`~plansim.fit.site.unknown_site_inputs` when the site is not known).
    omega_squared_sign : {"model", "as_printed"}
        Eq. (12)'s sign (:func:`plansim.estimate.jjf2003.rate_sensitivity`).
    lever_arm : (3, 3) array_like, optional
        The accelerometers' known lever arms from the table axis, m (row i: accelerometer i), a known input of
        the model (:class:`~plansim.fit.model.MeanModel`); default none, and P absorbs them.
    extra : dict, optional
        Further unknowns fitted jointly with θ: name -> (S_used, 6) array, the change of each used segment's
        means per unit of the unknown (an effect beyond eq. (1)/(2) that is linear in its size; see
        :mod:`plansim.diagnose`). Their estimates, u and ν are ``FitResult.extra``.
    between_noise : BetweenSegmentNoise, optional
        The noise between segments beyond the prediction, given rather than estimated from this fit's residuals
        (``plansim diagnose`` estimates it once from the largest model, so that it does not absorb the effects
        it tests for).
    stated_white : (6,) array_like, optional
        The sensor's stated white-noise densities (rad/s/√Hz for gx gy gz, m/s²/√Hz for ax ay az; NaN where not
        stated), as a scenario's ``[mimu.noise]`` gives them: the prior of the noise before a quantiser the noise
        does not dither, which the data show only weakly (:func:`plansim.fit.noise.quantised_noise_posterior`).
    stated_step : (6,) array_like, optional
        The acquisition's stated quantisation steps, SI (a scenario's ``[acquisition]``,
        :func:`plansim.fit.noise.stated_steps`): used only for a channel whose step the data cannot show
        (:func:`plansim.fit.noise.estimate_noise`).
    noise : NoiseEstimate, optional
        The noise of the recording's samples, as :func:`recording_noise` returns it for this recording,
        *stated_white* and *stated_step*: given, it is not estimated again (it depends on the samples alone,
        and ``plansim diagnose`` refits the same recording several times).
    moves : bool
        Also fit the gyros from the moves between static poses (:mod:`plansim.fit.moves`; default True). The
        joint fit and its result do not depend on it.
    held : HeldPriors, optional
        The Type B standard uncertainties of what the fit holds at nominal (a gyro's scale factor or
        cross-coupling, the accelerometers' shear, a g-sensitivity the moves need); default the data sheet's
        (:class:`~plansim.fit.identify.HeldPriors`), or a scenario's ``[reduction]`` (``scenario_fit_options``).
    progress : callable, optional
        ``progress(starts, None)`` after each start of the moves' search for the gyros' scale factors
        (:func:`plansim.fit.moves.fit_moves`), which on a long log whose moves fit no Kg takes a minute or more.

    Returns
    -------
    FitResult
    """
    given = dict(site=site, turntable=turntable, turntable_source=turntable_source,
                 reference_gravity=reference_gravity, omega_squared_sign=omega_squared_sign, lever_arm=lever_arm,
                 extra=extra, between_noise=between_noise, stated_white=stated_white, stated_step=stated_step,
                 held=held)
    site = Site() if site is None else site
    priors = HeldPriors() if held is None else held
    if not isinstance(priors, HeldPriors):
        raise TypeError(f"held = {held!r}: expected a plansim.fit.identify.HeldPriors or None")
    notes = [] if held is None else [
        f"what the fit holds at nominal carries the Type B u of {priors.source}: a gyro scale factor or "
        f"cross-coupling {priors.gyro:g}, the accelerometers' shear {priors.accel_cross:g}, a g-sensitivity "
        f"{float(to_unit(priors.g_sensitivity, 'rate_per_acceleration', 'deg/s/g')):g} (deg/s)/g; the unit's data "
        f"sheet: {priors.describe_data_sheet()}"]
    if turntable is None:
        turntable, turntable_source = TABLE_1_TURNTABLE, turntable_source or "JJF 2003 Table 1"
    schedule = recording.schedule
    use = _segment_use(schedule, recording)
    used, unused = use.used, use.unused
    if not used:
        raise ValueError("recording: no segment can be fitted; "
                         f"{len(unused)} segment(s) not used: " + "; ".join(f"{k}: {r}" for k, r in unused.items()))
    _refuse_constant_channels(recording)
    used_schedule = Schedule(tuple(schedule.segments[k] for k in used), procedure=schedule.procedure)
    on_table = any(s.orientation == "known" for s in used_schedule.segments)
    rate_column, angle_column = (schedule.import_notes.get(key) for key in (TABLE_RATE_NOTE, TABLE_ANGLE_NOTE))
    # a turn fitted by its angle carries the table's angle errors where the table gave it: its encoder's column,
    # or a table that set the poses and turned between them by the angles given (poses on a table, no rate column);
    # each rest's angle is off by the table's position accuracy and repeatability (docs/fitting.md)
    encoder = bool(use.angle_turns) and bool(angle_column or (on_table and not rate_column))
    turn_angles = (use.angle_turns, turntable.position_uncertainty if encoder else 0.0)
    if not on_table:
        # no pose on a table: its position errors have nothing to act on (the hand placement is fitted instead); a
        # turn fitted by its given rate is the table's (an imported steady turn), or its angle the table's rate
        # column's integral, whose rate errors stay
        zero = ErrorDistribution("uniform", 0.0)
        by_rate = any(s.is_rotating and s.rate_known for s in used_schedule.segments) or \
            bool(use.angle_turns and rate_column and not angle_column)
        if by_rate:
            turntable = dataclasses.replace(turntable, position_accuracy=zero, position_repeatability=zero,
                                            axis_perpendicularity=zero, platform_tilt=zero,
                                            fixture_perpendicularity=zero)
        else:
            turntable = Turntable(*([zero] * 7), rate_smoothness=0.0)
        kept = [(errors, why) for errors, why, on in (
            ("rate errors", "the turns' rates are the table's", by_rate),
            ("angle errors", f"the turns' angles are the table's column {angle_column!r}, off by its position "
             "accuracy and repeatability at each rest", encoder)) if on]
        if kept:
            turntable_source = (f"{turntable_source}: its {' and '.join(errors for errors, _ in kept)} only "
                                f"({'; '.join(why for _, why in kept)}; every pose is placed by hand)")
        else:
            turntable_source = "none: every pose and turn is by hand (no table)"
    model_schedule = Schedule(tuple(use.model_segments), procedure=schedule.procedure)
    rows = np.ones((len(used), 6), dtype=bool)
    rows[np.asarray(use.gyro_only, dtype=bool), 3:] = False  # a hand turn's accelerometers feel the hand
    rows = rows.ravel()
    select = np.eye(rows.size)[rows]
    if site.known:
        gravity, earth, site_inputs = site.gravity, site.earth_rate_vector, None
    else:
        gravity, u_gravity, earth, u_earth = unknown_site_inputs(site.earth_rate)
        site_inputs = (u_gravity, u_earth)
        notes.append(f"site not known: gravity {gravity:.6f} ± {u_gravity:.4f} m/s² and the Earth rate over every "
                     "latitude enter as Type B inputs (give --latitude/--height)")
    model = MeanModel(model_schedule, gravity, earth, hand_axes=use.hand_axes, lever_arm=lever_arm)
    means_all = np.asarray(recording.segment_means(), dtype=float)
    observed = means_all[used]
    extra = dict(extra or {})
    for name, columns in extra.items():
        if np.shape(columns) != observed.shape or not np.all(np.isfinite(columns)):
            raise ValueError(f"extra[{name!r}]: expected finite values of shape {observed.shape} (used segments x "
                             f"channels), got shape {np.shape(columns)}")
    E = np.column_stack([np.asarray(c, dtype=float).ravel() for c in extra.values()]) if extra else None
    n_extra = len(extra)
    theta0 = nominal_parameters()
    tilts0 = model.initial_tilts(observed[:, 3:])
    # at the nominal point: the nominal parameters and every pose as named (a hand-placed pose untilted), so that
    # what a tilt stands in for at first order (an accelerometer's cross-coupling) counts as not identified; a pose
    # tilted beyond APPROXIMATE_TILT about East or North is taken where the data put it in that component
    nominal_tilts = _far_tilts(tilts0, int(model.placed.sum()))
    if _judged is not None:  # the tilts a first fit found, its biases taken out (below)
        nominal_tilts = np.where(_judged != 0.0, _judged, nominal_tilts)
    ident = _identifiability_at(model, theta0, nominal_tilts, rows)
    J = model.parameter_jacobian(earth_rate=True, tilts=tilts0)
    mask = ident.mask
    if model.placed.any():
        notes.append(f"{int(model.placed.sum())} pose(s) placed by hand: each one's tilt from its nominal pose is "
                     "fitted (two nuisance parameters), and an unknown heading is averaged over")
    if use.hand_axes:
        notes.append("turns on a pose placed by hand about " + ", ".join("xyz"[a] for a in use.hand_axes) + ": the "
                     "mean rate is the table's rate or the reference angle over the duration, only the gyros are "
                     "fitted, and each turned axis's misalignment is fitted (two nuisance parameters)")
    held_kg = [PARAMETER_INDEX[p.name] for p in PARAMETERS
            if p.group == "Kg" and not mask[PARAMETER_INDEX[p.name]] and np.any(J[:, PARAMETER_INDEX[p.name]])]
    held_cross = _held_cross_couplings(ident, J) if model.n_tilts else []

    # noise: every segment that is not a move (any pose at rest shows the sensors' noise)
    noise_segments = _noise_segments(schedule)
    all_noise = recording_noise(recording, stated_white, stated_step) if noise is None else noise
    if all_noise.within_std.shape[0] != len(noise_segments):
        raise ValueError(f"noise: estimated over {all_noise.within_std.shape[0]} segments, but this recording has "
                         f"{len(noise_segments)} that are not moves; pass recording_noise(recording) of this "
                         "recording")
    keep = [noise_segments.index(k) for k in used]
    noise = all_noise.subset(keep)

    m = observed.ravel()
    times = _middle_times(recording, used)
    basis = ident.basis
    if model.n_tilts:
        basis = _held_at_nominal(basis, sorted({k for pair in held_cross for k in pair}), ident.rank,
                                 np.hstack([model.parameter_jacobian(earth_rate=False, tilts=nominal_tilts),
                                            model.tilt_jacobian(theta0, nominal_tilts, earth_rate=False)])[rows])
    theta, tilts, levels = theta0, tilts0, None
    slow = None
    # the data sheet as a prior (solve), once the data leave some direction to it: then in every later solve
    use_prior = False
    limits = priors.limits
    # Type B sensitivities at the nominal point, then at the estimate; then once more with the between-segment
    # noise the residuals show beyond the prediction (slow noise the segments are too short to show)
    for iteration in range(3):
        sources = _build_sources(model, theta, noise, turntable, site_inputs, held_kg, J, levels, tilts, priors,
                                 turn_angles)
        if iteration == 1:
            V_predicted = sources.covariance()
        if slow is not None:
            add_between_segment_noise(sources, slow, rows.reshape(observed.shape), times)
        V = sources.covariance()
        # the weights: a working covariance with each segment's quantisation error on its own. The full V (errors
        # of segments at nearly the same level shared, through the quantiser's harmonics) is what u propagates
        # through, for any weights; as weights its fine structure would let the fit cancel errors by contrasts
        # that hold only as exactly as the levels, the dither and the offset model do (docs/fitting.md)
        working = V
        if levels is not None and np.any(noise.quantisation_variance > 0):
            work = _build_sources(model, theta, noise, turntable, site_inputs, held_kg, J, None, tilts, priors,
                                  turn_angles)
            if slow is not None:
                add_between_segment_noise(work, slow, rows.reshape(observed.shape), times)
            working = work.covariance()
        W = whitening(working[np.ix_(rows, rows)]) @ select  # only the fitted rows
        stall: list = []
        try:
            solution = solve(model, basis, theta0, tilts0, m, W, J, extra=E, stalled=stall, prior=use_prior,
                              limits=limits)
        except ValueError:
            if use_prior:
                raise
            # a search that stops short may be walking a valley only the data sheet bounds: with it
            stall, use_prior = [], True
            solution = solve(model, basis, theta0, tilts0, m, W, J, extra=E, stalled=stall, prior=True, limits=limits)
        theta, tilts, gain, design, gain_z, chi2, c, prior_gains = solution
        rank, step_basis = ident.rank, basis
        if model.n_tilts:
            # at the fitted tilts, second-order terms separate what a tilt stood in for at the nominal point (an
            # accelerometer's cross-coupling): those combinations are freed when the data ask for them (χ² drops
            # by more than its 99 % quantile for as many degrees of freedom), from the first solution
            local = _identifiability_at(model, theta, tilts, rows)
            if local.rank > rank:
                second_stall: list = []
                try:
                    second = solve(model, local.basis, theta, tilts, m, W, J, linear_start=False, extra=E,
                                    stalled=second_stall, prior=use_prior, limits=limits)
                except ValueError:
                    second = None
                if second is not None and chi2 - second[5] > chi2_quantile(local.rank - rank, 0.99):
                    theta, tilts, gain, design, gain_z, chi2, c, prior_gains = second
                    rank, step_basis, stall = local.rank, local.basis, second_stall
        if not use_prior and weak_directions(
                W @ design, np.hstack([step_basis[:len(theta0)], np.zeros((len(theta0), n_extra))]), limits)[1].any():
            # the data leave a direction to what a data sheet already says: the data sheet holds it (estimate and
            # u alike), from here on
            use_prior, stall = True, []
            try:  # from where the data alone left it, or, where the prior's pull along a curved valley takes
                # longer than the search may walk, from the start
                solution = solve(model, step_basis, theta, tilts, m, W, J, linear_start=False, extra=E,
                                  stalled=stall, prior=True, limits=limits)
            except ValueError:
                stall = []
                solution = solve(model, step_basis, theta0, tilts0, m, W, J, extra=E, stalled=stall, prior=True,
                                  limits=limits)
            theta, tilts, gain, design, gain_z, chi2, c, prior_gains = solution
        J = model.parameter_jacobian(earth_rate=True, tilts=tilts)
        fitted = model.means(theta, tilts) + ((E @ c).reshape(observed.shape) if n_extra else 0.0)
        hat = design @ gain_z
        # what the data sheet's prior puts into the fitted means (its mean's Type B u through their gain on it)
        prior_columns = None if prior_gains is None else prior_gains[1] * limits[None, :]
        held_by_prior = 0.0 if prior_columns is None else prior_columns @ prior_columns.T
        # the fitted levels of the segment means and their uncertainties (for the quantiser's correlation)
        levels = (fitted, hat @ _prior_covariance(V, sources, noise, fitted, J) @ hat.T + held_by_prior)
        if iteration == 1:
            residual_predicted = m - fitted.ravel()  # the fit with the predicted noise alone, for its χ²
            if between_noise is None and prior_gains is not None:
                # the noise between segments is the data's: estimated from the residual the data alone leave (one
                # Gauss–Newton step without the prior, from here: exact where the model is linear), not from one the
                # data sheet's pull puts into the means. Where the unit lies outside its data sheet, the pull's
                # residual would otherwise read as slow noise, and the conflict it is (data_sheet_conflict) would
                # hide in the noise it inflated; where the data sheet holds, the two residuals differ by (u/U)².
                data_hat = design @ _step_without_prior(W, design)
                residual_data = residual_predicted - data_hat @ residual_predicted
            else:
                data_hat, residual_data = hat, residual_predicted
            slow = between_noise if between_noise is not None else \
                between_segment_noise(residual_data, V, data_hat, rows.reshape(observed.shape), times,
                                      coupled=model.n_tilts > 0)
            if not np.any(slow.variance > 0):
                break
    if stall:
        evaluations, decrease, weak, n_weak = stall[-1]
        notes.append(f"the joint fit stopped after {evaluations} evaluations, where one more Gauss–Newton step "
                     f"would lower chi2 by {decrease:.2g}" + (
                         f" along what the data determine and by {weak:.2g} along {n_weak} direction(s) they "
                         "determine only weakly (below the 99 % point for as many degrees of freedom; the "
                         "parameters along them are listed as determined only weakly where their u shows it)"
                         if n_weak else "") + ": it was walking a direction the data barely determine (poses "
                     "placed by hand whose gravity directions leave part of the model nearly free); the "
                     "estimates' u along it are correspondingly large")
    if prior_gains is not None:
        notes.append("the data leave some direction of the fitted parameters no better determined than the unit's "
                     "data sheet says (a step of one u along it moves a parameter beyond its group's limit, "
                     f"{priors.source}: {priors.describe_data_sheet()}): the fit carries the data sheet as a prior "
                     "of every parameter (nominal ± those limits, the 'data_sheet' part of u), which holds the "
                     "estimate and its u along those directions and pulls a well-determined one by (u/U)² of its "
                     "distance from nominal; a parameter that owes more than half its variance to it is listed as "
                     "determined only weakly")
    conflict = {} if prior_gains is None else data_sheet_conflict(theta - nominal_parameters(), limits,
                                                                   prior_gains[0], mask)
    held_sources = Sources(len(m))
    bound = _held_bound(model, theta, tilts, rows, W, ident.rank, rank, held_cross, priors.accel_cross) \
        if held_cross else []
    for (a, b), u in zip(held_cross, bound):  # at the fitted tilts (J): the part the tilts do not take up
        held_sources.add(J[:, a] + J[:, b], u, math.inf, "held")
    every_source = sources.joined(held_sources)
    if conflict:
        alone, alone_u = _data_alone(theta, step_basis, design, W, m - fitted.ravel(), every_source, mask)
        for group, entry in conflict.items():
            entry["data_alone"] = {p.name: (float(alone[k]), float(alone_u[k])) for k, p in enumerate(PARAMETERS)
                                   if p.group == group and mask[k]}
    contradicted = [group for group, entry in conflict.items() if entry["contradicted"]]
    if contradicted:
        notes.append("the data contradict the data sheet's " + ", ".join(
            f"{group} ({describe_conflict(conflict[group])})" for group in contradicted)
            + ": the unit lies outside what its data sheet states for them (or the data sheet's u is too small), and "
            "the prior pulls those estimates towards nominal (the data alone: one Gauss–Newton step without the "
            "prior, u from the same sources); state the data sheet again (scenario [reduction] data_sheet_*) or fit "
            "with the consumer default")
    joint = propagate(METHOD_JOINT, gain, every_source, mask,
                      prior_gain=None if prior_gains is None else prior_gains[0], prior_u=limits)
    joint = Method(METHOD_JOINT, np.where(mask, theta, math.nan), joint.u, joint.dof, joint.contributions)
    shear = _accel_shear(ident, mask, theta, gain, sources, held_cross, bound, J,
                         None if prior_gains is None else (prior_gains[0], limits)) if model.n_tilts else ()
    residual = m - fitted.ravel()
    project = np.eye(len(m)) - hat
    residual_cov = project @ V @ project.T + held_by_prior
    residual_sd = np.where(rows, np.sqrt(np.maximum(np.diag(residual_cov), 0.0)), math.nan).reshape(observed.shape)
    # χ² of the fit with the predicted noise (the within-segment model, quantisation, table, site) against it,
    # not against the between-segment part estimated from these same residuals
    chi2 = float(np.sum((whitening(V_predicted[np.ix_(rows, rows)]) @ select @ residual_predicted) ** 2))
    # with the data sheet's prior, the effective number of fitted combinations: the trace of the hat matrix
    # (each direction the data determine counts 1, one the prior holds less)
    chi2_dof = int(rows.sum()) - (rank + n_extra if prior_gains is None else int(round(float(np.trace(hat)))))
    extra_method = None
    if n_extra:
        every = np.ones(n_extra, dtype=bool)
        extra_method = propagate("joint_wls_extra", gain_z[gain_z.shape[0] - n_extra:], sources, every,
                                 prior_gain=None if prior_gains is None else
                                 prior_gains[2][gain_z.shape[0] - n_extra:], prior_u=limits)
        extra_method = Method("joint_wls_extra", np.asarray(c, dtype=float), extra_method.u, extra_method.dof,
                              extra_method.contributions)

    # the specification's estimators where the procedure is complete
    spec, spec_note = None, ""
    spec_bias = np.full(len(PARAMETER_NAMES), math.nan)
    g_ref = gravity if reference_gravity is None else reference_gravity
    try:
        check_design(schedule)
    except ValueError as exc:
        spec_note = f"the specification's estimators need the whole procedure: {exc}"
    else:
        M = reduction_matrix(schedule, g_ref, omega_squared_sign)
        if M is None:
            spec_note = "the specification's reduction is not linear for this schedule"
        else:
            needed = np.flatnonzero(np.any(M != 0, axis=1)) // 6
            missing = sorted(set(needed.tolist()) - {k for k in used if schedule.segments[k].orientation == "known"})
            if missing:
                spec_note = (f"the specification's estimators use segment(s) {missing}, whose pose or rate is not "
                             "known")
            else:
                rows6 = (np.asarray(used)[:, None] * 6 + np.arange(6)[None, :]).ravel()
                spec_gain = M[rows6].T  # (39, 6S_used)
                estimate = means_all.ravel() @ M
                all_mask = np.ones(len(PARAMETER_NAMES), bool)
                spec = propagate(METHOD_SPEC, spec_gain, sources, all_mask,
                                 f"JJF 2003 eq. (3)-(13), 1 g = {g_ref:.8g} m/s^2")
                spec = Method(METHOD_SPEC, estimate, spec.u, spec.dof, spec.contributions, spec.note)
                if mask.all():
                    spec_bias = spec_gain @ fitted.ravel() - theta
    if spec is None and not spec_note:
        spec_note = "not run"
    # repeated settings against the prediction (not against the between-segment noise fitted to these residuals)
    between = between_segments(used_schedule, residual, project @ V_predicted @ project.T, project, sources)
    notes += _table_poses_note(used_schedule, between)
    result = FitResult(site=site, turntable_source=turntable_source, identifiability=ident, used=tuple(used),
                     tilts=np.asarray(tilts)[:2 * int(model.placed.sum())].reshape(-1, 2),
                     placed=tuple(np.asarray(used)[model.placed].tolist()),
                     hand_axes=use.hand_axes, axis_tilts=np.asarray(tilts)[2 * int(model.placed.sum()):].reshape(-1, 2),
                     fitted_rows=rows.reshape(observed.shape),
                     unused=unused, labels=tuple(s.label for s in used_schedule.segments), observed=observed,
                     fitted=fitted, residual_sd=residual_sd, noise=noise, joint=joint, spec=spec,
                     spec_note=spec_note, spec_bias=spec_bias, chi2=chi2, chi2_dof=chi2_dof,
                     chi2_verdict=chi2_verdict(chi2, chi2_dof, DIAGNOSE_NEXT), between=between,
                     attrs=dict(getattr(recording, "attrs", {}) or {}), notes=tuple(notes) + noise.notes,
                     model=model, theta=np.asarray(theta, dtype=float), nuisance=np.asarray(tilts, dtype=float),
                     covariance=V, whitening=W, design=design, rows=rows,
                     segment_times=times, basis=step_basis, extra=extra_method,
                     extra_names=tuple(extra), covariance_predicted=V_predicted, between_noise=slow,
                     gain=gain, sources=sources, held_sources=held_sources, held=priors,
                     prior_gain=None if prior_gains is None else prior_gains[0], data_sheet_conflict=conflict,
                     shear=shear)
    if _judged is None and model.placed.any():
        # a pose's tilt as the import read it carries the accelerometers' biases (0.5 m/s² tilts the raw specific
        # force by 3°): judged again from this fit's tilts, a component no cross-coupling the shear's prior allows
        # could stand in for counts, and where that lets the poses determine more, the recording is fitted again
        # with what they identify decided there
        judged = _far_tilts(tilts, int(model.placed.sum()), TILT_BEYOND_SHEAR * priors.accel_cross)
        point = np.where(judged != 0.0, judged, nominal_tilts)
        if _identifiability_at(model, theta0, point, rows).rank > ident.rank:
            try:
                again = fit_recording(recording, noise=all_noise, moves=False, _judged=judged, **given)
            except ValueError:  # the first fit stands
                again = None
            if again is not None:
                result = dataclasses.replace(again, notes=again.notes + (
                    "what the recording identifies was decided with the poses where this fit found them (their "
                    f"tilt components beyond {math.degrees(TILT_BEYOND_SHEAR * priors.accel_cross):.2g}°, more "
                    "than an accelerometer cross-coupling within five times its prior could stand in for)",))
    if moves:
        transitions, unused_moves = find_transitions(recording)
        try:
            move_fit = fit_moves(recording, result, transitions, unused_moves, all_noise, progress=progress)
        except MovesNotFitted as why:  # the poses' fit stands without them; say why
            move_fit = None
            result = dataclasses.replace(result, notes=result.notes + (str(why),))
        if move_fit is not None:
            unused_note = {k: v for k, v in unused.items() if "a move between poses" not in v}
            result = dataclasses.replace(result, moves=move_fit, unused=unused_note,
                                         notes=result.notes + move_fit.notes)
    reversed_axes = [] if _judged is not None else reversed_axis_notes(  # once, on the outermost fit
        result.joint.estimate, result.moves.method.estimate if result.moves else None)
    if reversed_axes:
        result = dataclasses.replace(result, notes=result.notes + tuple(reversed_axes))
    return result


def _middle_times(recording, used) -> np.ndarray:
    """The middle time of each used segment from the recording's first sample, s."""
    segments = recording.schedule.segments
    return np.array([(int(recording.first_sample[k]) + 0.5 * segments[k].samples) / segments[k].sample_rate
                     for k in used], dtype=float)


