"""GUM uncertainty budgets derived from a scenario's schedule and estimators (JCGM 100:2008).

The law of propagation of uncertainty (JCGM 100 5.1.2, eq. (10); 5.2.2, eq. (13) for the correlated
drift) is applied to the *actual* data reduction of JJF 2003-2022 and the *actual* design: the
scenario's schedule, table and fixture errors, noise, drift and acquisition. The measurement model
of every parameter is

    Ŷ = R(m̄(X)),   E = Ŷ − Y,

where ``m̄`` are the segment means (eq. (3)) as functions of the input quantities ``X`` (the unit's
true parameters, every table and fixture error, the noise of each segment mean) and ``R`` is the
JJF 2003 reduction (eq. (4)-(13)), which is linear in the segment means, so its matrix
(:func:`estimator_matrix`) is obtained exactly by applying it to unit vectors. The output quantity
of each budget is the measurement error ``E`` of the parameter in SI: its estimate ``y`` is the
error at the expectation of the inputs (the sum of the systematic effects the specification's
estimators do not correct) and ``u_c(y)`` is the standard uncertainty of the calibrated value.

Input quantities (one budget line per group of independent components):

- **Table and fixture errors** (type B, JJF 2003 Table 1, §6.2): position accuracy and
  repeatability (per segment and axis), axis perpendicularity, platform tilt, fixture
  perpendicularity, systematic rate error, rate error per point. Drawn by the simulator from the
  scenario's distributions (``scenario.turntable.<error>``: a ± limit is rectangular, GUM 4.3.7;
  a stated uncertainty is normal, 4.3.3). Sensitivity coefficients by central finite differences
  of :func:`plansim.simulate.arguments.noise_free_segment_means` followed by the reduction, one
  component of the draws vector at a time with a step of its standard uncertainty (GUM 5.1.3
  note 2), around :func:`plansim.simulate.arguments.nominal_draws`. A group's contribution is
  ``sqrt(Σ (c_i u_i)²)`` over its independent components; its *group-equivalent* sensitivity is
  that contribution divided by the components' common ``u``.
- **Table start angle** of the rotating segments (type B, uniform on [0, 2π)). A segment that is
  not a whole number of turns does not average the Earth rate or a tilted gravity vector away. The
  output is a trigonometric polynomial of degree ≤ 3 in the start angle (see
  :mod:`plansim.simulate.segment_path`), so its variance is obtained exactly from
  :data:`PHASE_NODES` equally spaced angles rather than linearised. Sensitivities of the other
  inputs are averaged over the same angles (the expectation of the linearised model).
- **Unit under calibration** (type B): the spread of the true parameters between units
  (``mimu.truth_spread``) enters only through the error's dependence on the true value
  (``∂E/∂Y = R·∂m̄/∂Y − 1``, zero for an exact estimator).
- **White noise** of every segment mean (type A, GUM 4.2): ``u = N/√T`` per channel (angle or
  velocity random walk ``N``, dwell ``T``), ``ν = n − 1`` from the ``n`` samples of the segment,
  propagated through the estimator matrix.
- **Drift** (type B: the Allan-variance coefficients of the scenario): the bias-instability and
  Gauss–Markov processes and the random walk, held over the drift update interval exactly as the
  simulator holds them. The covariance of all segment means is derived exactly from the state
  recursion (:func:`drift_covariance`), including the settling gaps, and propagated with GUM
  5.2.2 (correlated inputs).
- **Quantisation** (type B): Appendix A's rectangular model, in the form that holds for a
  quantiser with Gaussian noise at its input (Widrow; :func:`quantisation_variance`). Without
  noise (no dither) it is the rectangular ±q/2 of one reading, ``u = q/√12`` per segment mean
  (Appendix A eq. (A.3), A.1.2.2); with full dither each sample adds ``q²/12`` and the mean of
  ``n`` samples ``q²/(12 n)``; in between the part the noise does not average is given by the
  damped Fourier series of the sawtooth. Appendix A treats its readings as independent; the
  segments of one channel are not when they read the same or nearby codes without dither (they
  share the quantiser and the unknown offset of the channel), and :func:`quantisation_covariance`
  gives their covariance exactly (GUM 5.2.2); ``evaluate_gum(..., quantisation_correlation=False)``
  keeps Appendix A's independence.
- **Rate smoothness** (type B, Table 1): the per-sample rate jitter's segment mean, common to the
  channels of a segment, through the outputs' derivative with respect to the rate; the jitter also
  dithers the quantiser of the rotating segments.

Combined standard uncertainty ``u_c`` (5.1.2), effective degrees of freedom by the
Welch–Satterthwaite formula (G.4.1, eq. (G.2b)), coverage factor ``k`` from the
t-distribution (G.3.4, G.4.1; ν_eff not truncated, i.e. interpolated) and ``U = k·u_c`` (6.2.1).
Degrees of freedom of type B inputs given as limits are infinite (G.4.2: the limits are taken as
exactly known); a stated relative uncertainty of an uncertainty is not part of a scenario.

Systematic effects the specification's estimators do not correct (Earth rate, accelerometer lever
arm, the value of g used as reference, the ω² sign convention, temperature and sensor effects
outside eq. (1)/(2)) are reported per parameter as a **bias**, computed from the noise-free
segment means with and without the effect. GUM 3.2.3-3.2.4 asks that such effects be corrected;
plansim reports their size next to ``u_c`` instead of hiding them in it.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy import special  # the quantiles themselves: scipy.stats takes 1.4 s to import

from plansim.estimate import reduce
from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS
from plansim.config import ErrorDistribution, Scenario
from plansim.simulate.arguments import (drift_coefficient_table, kernel_arguments, nominal_draws,
                                        noise_free_segment_means)
from plansim.kernels.layout import HEAD, PER_SEGMENT
from plansim.uncertainty.appendix_a import APPENDIX_A, AppendixABudget, reading_unit_in_si

__all__ = [
    "CATEGORIES",
    "DEFAULT_COVERAGE_PROBABILITY",
    "PHASE_NODES",
    "AppendixAView",
    "GumEvaluation",
    "InputContribution",
    "ParameterBudget",
    "SystematicEffect",
    "combine",
    "coverage_factor",
    "drift_covariance",
    "estimator_matrix",
    "evaluate_gum",
    "quantisation_covariance",
    "quantisation_variance",
    "systematic_effects",
    "welch_satterthwaite",
]

#: Coverage probability of the expanded uncertainty (GUM 6.2.2; the 95 % of Appendix A's k = 2).
DEFAULT_COVERAGE_PROBABILITY = 0.95

#: Start angles at which the noise-free means are evaluated: the means are trigonometric
#: polynomials of degree ≤ 3 in the start angle, so averages of their products (degree ≤ 6) over
#: ≥ 7 equally spaced angles are exact.
PHASE_NODES = 8

#: Budget lines below this fraction of u_c are left out (10⁻¹² of the variance: numerical noise).
NEGLIGIBLE = 1e-6

#: Appendix A's three components, and the budget lines that belong to each.
CATEGORIES = ("table", "acquisition", "repeatability", "unit")

_CHANNEL_UNITS = ("rad/s",) * 3 + ("m/s^2",) * 3


# ----------------------------------------------------------------------------- GUM arithmetic


def _check_dof(dof) -> np.ndarray:
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
    """
    u = np.abs(np.asarray(contributions, dtype=float))
    dof = _check_dof(dofs)
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

    ``u_c = sqrt(Σ u_i²)`` (JCGM 100 5.1.2, eq. (10) with ``u_i = |c_i| u(x_i)``) and
    :func:`welch_satterthwaite`.
    """
    u = np.asarray(contributions, dtype=float)
    return float(math.sqrt(np.sum(u**2))), welch_satterthwaite(u, dofs)


def coverage_factor(dof: float, coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY) -> float:
    """``k_p = t_p(ν_eff)`` of the t-distribution, JCGM 100 G.3.4 and G.4.1 eq. (G.1e).

    A non-integer ``ν_eff`` is used as it is (equivalent to interpolating Table G.2, G.4.1 note 1);
    ``ν = inf`` gives the normal quantile (1.960 for 95 %).
    """
    if not (isinstance(coverage_probability, (int, float)) and 0.0 < coverage_probability < 1.0):
        raise ValueError(f"coverage_probability = {coverage_probability!r}: must lie strictly between 0 and 1")
    (dof,) = _check_dof([dof])
    q = 0.5 * (1.0 + coverage_probability)
    if math.isinf(dof):
        return float(special.ndtri(q))  # the normal quantile
    return float(special.stdtrit(dof, q))  # Student's t quantile


# ----------------------------------------------------------------------------- the model's pieces


def estimator_matrix(scenario: Scenario) -> np.ndarray:
    """The JJF 2003 reduction as a matrix: ``(39, S, 6)`` with ``estimate = Σ M[:, s, c]·mean[s, c]``.

    :func:`plansim.estimate.reduce` is linear in the segment means (eq. (5), (7), (10), (12)-(13)
    are linear least squares and differences with the nominal schedule), so applying it to the
    ``6·S`` unit vectors gives its matrix exactly.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.scenario.Scenario")
    n_seg = len(scenario.schedule)
    unit = np.eye(6 * n_seg).reshape(6 * n_seg, n_seg, 6)
    columns = reduce(unit, scenario.schedule, scenario.reduction.reference_gravity,
                     scenario.reduction.omega_squared_sign)  # (6S, 39)
    return np.ascontiguousarray(columns.T.reshape(N_PARAMETERS, n_seg, 6))


def _process_covariance(coefficients: np.ndarray, gaps: np.ndarray, sigma: float, tau: float | None) -> np.ndarray:
    """Covariance (S, S) of the segment means of one held drift process (exact state recursion).

    ``coefficients`` (S, 5): unit-σ ``a, c, L11, L21, L22`` of
    :func:`plansim.simulate.segment_path.drift_coefficients` (``mean = a·x0 + σL11 z1``,
    ``end = c·x0 + σ(L21 z1 + L22 z2)``); ``gaps`` (S,): settling before each segment, over which the
    state is advanced exactly (φ = exp(−Δ/τ), or a random walk when ``tau`` is None).
    """
    n_seg = len(gaps)
    variance = sigma**2 if tau is not None else 0.0  # Gauss–Markov stationary at the start, walks at 0
    with_means = np.zeros(n_seg)  # Cov(state, mean_j) for the segments done so far
    cov = np.zeros((n_seg, n_seg))
    for s in range(n_seg):
        gap = gaps[s]
        if gap > 0.0:
            if tau is None:
                variance += sigma**2 * gap
            else:
                phi = math.exp(-gap / tau)
                variance = phi**2 * variance + sigma**2 * (1.0 - phi**2)
                with_means *= phi
        a, c, l11, l21, l22 = coefficients[s]
        cov[s, :s] = a * with_means[:s]
        cov[:s, s] = cov[s, :s]
        cov[s, s] = a**2 * variance + sigma**2 * l11**2
        end_with_means = c * with_means
        end_with_means[s] = c * a * variance + sigma**2 * l11 * l21
        variance = c**2 * variance + sigma**2 * (l21**2 + l22**2)
        with_means = end_with_means
    return cov


def drift_covariance(scenario: Scenario) -> np.ndarray:
    """Covariance of the drift part of every segment mean, ``(6, S, S)`` per channel gx … az.

    Derived from the model the simulator uses (:mod:`plansim.simulate.sample_path`): first-order
    Gauss–Markov bias instability (σ from :func:`plansim.simulate.arguments.bias_instability_sigma`,
    correlation time ``bias_instability_correlation_time``), Gauss–Markov drift
    (``*_markov_sigma``, ``markov_correlation_time``) and random walk, each advanced exactly every
    ``drift_update_interval`` and held in between; Gauss–Markov processes stationary at the start
    of the test, random walks starting at zero. The recursion over the segments (settling gaps
    included) gives the covariance exactly; channels and processes are independent.
    """
    args = kernel_arguments(scenario)
    noise = args["noise"]  # (6, 4): white, bias-instability σ, random-walk coefficient, Gauss–Markov σ
    table = drift_coefficient_table(scenario)  # (S, 3, 5)
    gaps = np.array([s.settle for s in scenario.schedule.segments], dtype=float)
    n = scenario.noise
    n_seg = len(gaps)
    out = np.zeros((6, n_seg, n_seg))
    for c in range(6):
        for p, (sigma, tau) in enumerate(((noise[c, 1], n.bias_instability_correlation_time),
                                          (noise[c, 3], n.markov_correlation_time),
                                          (noise[c, 2], None))):
            if sigma > 0.0:
                out[c] += _process_covariance(table[:, p, :], gaps, float(sigma), tau)
    return out


def quantisation_variance(step: float, sigma: float, samples: int) -> tuple[float, float]:
    """Variance of the quantisation error of a segment mean, and the part the noise does not average.

    The error of one reading ``Q(x) − x`` of ``x = μ + σZ`` is a sawtooth; with the offset μ
    unknown (uniform modulo q, the state of knowledge behind Appendix A's rectangular model) it is
    rectangular ±q/2 whatever σ, variance q²/12. Its conditional mean given μ — the part common to
    all samples of a segment — has the Fourier series Σ_k (−1)^{k+1} q/(πk) γ_k sin(2πkμ/q) with
    γ_k = exp(−2π²k²σ²/q²) (Widrow's quantisation theorem; :mod:`plansim.simulate.segment_path`),
    hence variance ``B = (q²/2π²) Σ_k γ_k²/k²``; the rest, ``q²/12 − B``, varies from sample to
    sample independently (given μ the samples are independent) and is averaged over the ``n``
    samples; the cross term with the noise averages to zero over μ.

    Parameters
    ----------
    step : float
        Quantisation step q (> 0).
    sigma : float
        Standard deviation of the white noise of one sample at the quantiser input (≥ 0).
    samples : int
        Samples n in the segment mean.

    Returns
    -------
    variance : float
        ``B + (q²/12 − B)/n``: ``q²/12`` without noise (Appendix A, u = q/√12 = δ/√3 in its
        notation), ``q²/(12n)`` with full dither.
    undithered_fraction : float
        ``B/(q²/12)``: 1 without dither, 0 with full dither.
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: the quantisation step must be finite and > 0")
    if not (math.isfinite(sigma) and sigma >= 0):
        raise ValueError(f"sigma = {sigma!r}: the noise standard deviation must be finite and >= 0")
    if isinstance(samples, bool) or not isinstance(samples, (int, np.integer)) or samples < 1:
        raise ValueError(f"samples = {samples!r}: expected a whole number >= 1")
    full = step**2 / 12.0
    r = sigma / step
    if r == 0.0:
        fraction = 1.0
    else:
        # γ_k² = exp(−4π²k²r²) < 1e-40 beyond k_max; cap the terms and add the tail Σ_{k>K} 1/k² ≈ 1/K
        k_max = int(math.ceil(math.sqrt(92.0) / (2.0 * math.pi * r))) + 1
        cap = 1_000_000
        k = np.arange(1, min(k_max, cap) + 1, dtype=float)
        series = float(np.sum(np.exp(-4.0 * math.pi**2 * k**2 * r**2) / k**2))
        if k_max > cap:
            series += 1.0 / cap
        fraction = min(series * 6.0 / math.pi**2, 1.0)
    bias = fraction * full
    return bias + (full - bias) / int(samples), fraction


# ----------------------------------------------------------------------------- the result objects


@dataclass(frozen=True)
class InputContribution:
    """One line of a budget: an input quantity (or a group of independent components).

    Attributes
    ----------
    name : str
        The input, e.g. ``"position accuracy"``.
    category : str
        Appendix A's component it belongs to: ``"table"`` (u1), ``"acquisition"`` (u2),
        ``"repeatability"`` (u3) or ``"unit"`` (the unit under calibration).
    evaluation : str
        ``"A"`` or ``"B"`` (GUM 4.2, 4.3).
    distribution : str
        The distribution assigned to each component (rectangular ±a, normal, …).
    standard_uncertainty : float
        ``u(x_i)`` of one component, in ``input_unit`` (the RMS over the components if they differ);
        ``nan`` where the line is not linearised.
    input_unit : str
        SI unit of the input.
    sensitivity : float
        ``c_i`` (one component), or the group-equivalent ``contribution / standard_uncertainty``;
        ``nan`` where the line is not linearised (start angle, drift).
    contribution : float
        ``u_i(y)``: the line's contribution to the parameter's standard uncertainty, SI.
    dof : float
        Degrees of freedom ``ν_i`` (Welch–Satterthwaite within the group; ``inf`` for type B).
    components : int
        Number of independent components in the group.
    note : str
        How the line was evaluated.
    """

    name: str
    category: str
    evaluation: str
    distribution: str
    standard_uncertainty: float
    input_unit: str
    sensitivity: float
    contribution: float
    dof: float
    components: int
    note: str = ""

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class SystematicEffect:
    """An effect the JJF 2003 estimators do not correct, as a bias of one parameter (SI)."""

    name: str
    bias: float
    note: str = ""

    def as_dict(self) -> dict:
        return dataclasses.asdict(self)


@dataclass(frozen=True)
class AppendixAView:
    """The Appendix A budget that applies to a parameter, in its reading unit and in SI.

    Attributes
    ----------
    item : str
        ``"A.1"`` … ``"A.5"``.
    reading_unit_si : float
        SI size of one reading unit for this parameter (:func:`reading_unit_in_si`).
    printed_u : tuple of float
        ``(u1, u2, u3)`` as printed, reading units.
    printed_uc, printed_U : float
        ``u_c`` and ``U`` (k = 2) as printed, reading units.
    same_inputs_gum_uc, same_inputs_gum_U : float
        The printed inputs recombined by the GUM law of propagation (the linear sums of u3 replaced
        by ``c·√n·u``, :attr:`UncertaintyComponent.gum_standard_uncertainty`), reading units, k = 2.
    plansim_u : tuple of float
        This scenario's GUM budget grouped as Appendix A groups it: table (u1), acquisition (u2),
        repeatability (u3: white noise and drift), reading units.
    plansim_uc, plansim_U95 : float
        This scenario's ``u_c`` and ``U95``, reading units.
    """

    item: str
    reading_unit_si: float
    printed_u: tuple[float, float, float]
    printed_uc: float
    printed_U: float
    same_inputs_gum_uc: float
    same_inputs_gum_U: float
    plansim_u: tuple[float, float, float]
    plansim_uc: float
    plansim_U95: float

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["printed_u"] = list(self.printed_u)
        d["plansim_u"] = list(self.plansim_u)
        return d


@dataclass(frozen=True)
class ParameterBudget:
    """The GUM budget of one JJF 2003 parameter (output quantity: its error E = Ŷ − Y, SI).

    Attributes
    ----------
    name, unit : str
        Parameter symbol and SI unit.
    truth : float
        Nominal true value (the linearisation point).
    estimate : float
        ``y``: the error at the expectation of the inputs — the sum of the uncorrected systematic
        effects (GUM 4.1.4).
    inputs : tuple of InputContribution
        The budget lines, largest contribution first; lines with zero contribution are omitted.
    combined_standard_uncertainty : float
        ``u_c(y)`` (GUM 5.1.2, 5.2.2).
    effective_dof : float
        ``ν_eff`` (G.4.1).
    coverage_factor : float
        ``k_p`` for ``coverage_probability`` (G.3.4).
    expanded_uncertainty : float
        ``U_p = k_p·u_c`` (6.2.1).
    coverage_probability : float
        ``p``.
    systematic_effects : tuple of SystematicEffect
        Uncorrected effects, each as a bias (nonzero ones only).
    largest_second_order : float
        Largest ``½|∂²E/∂x_i²|·u(x_i)²`` of the linearised inputs, SI (GUM 5.1.2 note: a check of
        the first-order approximation; compare with ``u_c``).
    appendix_a : AppendixAView or None
        The Appendix A budget of the parameter, where one applies.
    """

    name: str
    unit: str
    truth: float
    estimate: float
    inputs: tuple[InputContribution, ...]
    combined_standard_uncertainty: float
    effective_dof: float
    coverage_factor: float
    expanded_uncertainty: float
    coverage_probability: float
    systematic_effects: tuple[SystematicEffect, ...]
    largest_second_order: float
    appendix_a: AppendixAView | None = None

    def contribution(self, name: str) -> float:
        """The contribution of the input *name* (0 if the budget has no such line)."""
        for line in self.inputs:
            if line.name == name:
                return line.contribution
        return 0.0

    def category_uncertainty(self, category: str) -> float:
        """The lines of one Appendix A category combined in quadrature (drift and noise are
        independent of each other and of the table errors)."""
        if category not in CATEGORIES:
            raise ValueError(f"category = {category!r}; allowed: {', '.join(map(repr, CATEGORIES))}")
        return math.sqrt(sum(line.contribution**2 for line in self.inputs if line.category == category))

    def as_dict(self) -> dict:
        return {
            "name": self.name, "unit": self.unit, "truth": self.truth, "estimate": self.estimate,
            "inputs": [line.as_dict() for line in self.inputs],
            "combined_standard_uncertainty": self.combined_standard_uncertainty,
            "effective_dof": _json_number(self.effective_dof), "coverage_factor": self.coverage_factor,
            "expanded_uncertainty": self.expanded_uncertainty, "coverage_probability": self.coverage_probability,
            "systematic_effects": [e.as_dict() for e in self.systematic_effects],
            "largest_second_order": self.largest_second_order,
            "appendix_a": None if self.appendix_a is None else self.appendix_a.as_dict(),
        }


def _json_number(value: float):
    """``inf`` as the string ``"inf"`` (JSON has no infinity)."""
    return "inf" if isinstance(value, float) and math.isinf(value) else value


@dataclass(frozen=True)
class GumEvaluation:
    """GUM budgets of all 39 parameters of a scenario, and the covariance of their errors.

    Attributes
    ----------
    scenario : str
        Scenario name.
    budgets : tuple of ParameterBudget
        In the order of :data:`plansim.model.parameters.PARAMETER_NAMES`.
    covariance : ndarray (39, 39)
        Covariance of the parameter errors from every input (GUM 5.2.2; JCGM 102 6.2 for the
        multivariate law of propagation ``U_y = C_x U_x C_xᵀ``), SI.
    coverage_probability : float
        ``p`` of the expanded uncertainties.
    """

    scenario: str
    budgets: tuple[ParameterBudget, ...]
    covariance: np.ndarray
    coverage_probability: float

    def budget(self, name: str) -> ParameterBudget:
        """The budget of parameter *name*."""
        if name not in PARAMETER_INDEX:
            raise ValueError(f"unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        return self.budgets[PARAMETER_INDEX[name]]

    @property
    def estimate(self) -> np.ndarray:
        """``y`` of every parameter (39,)."""
        return np.array([b.estimate for b in self.budgets])

    @property
    def standard_uncertainty(self) -> np.ndarray:
        """``u_c`` of every parameter (39,)."""
        return np.array([b.combined_standard_uncertainty for b in self.budgets])

    @property
    def expanded_uncertainty(self) -> np.ndarray:
        """``U_p`` of every parameter (39,)."""
        return np.array([b.expanded_uncertainty for b in self.budgets])

    def correlation(self) -> np.ndarray:
        """Correlation matrix of the parameter errors (GUM 5.2.2, eq. (14)); 0 where a ``u_c`` is 0."""
        u = np.sqrt(np.diag(self.covariance))
        scale = np.where(u > 0, u, np.inf)
        r = self.covariance / np.outer(scale, scale)
        np.fill_diagonal(r, np.where(u > 0, 1.0, 0.0))
        return r


# ----------------------------------------------------------------------------- systematic effects


def _phase_grid_draws(scenario: Scenario, draws: np.ndarray | None = None) -> np.ndarray:
    """(J, D): *draws* (default nominal) with every segment's start angle at 2πj/J."""
    base = nominal_draws(scenario) if draws is None else np.asarray(draws, dtype=float)
    n_seg = len(scenario.schedule)
    grid = np.tile(base, (PHASE_NODES, 1))
    phases = 2.0 * math.pi * np.arange(PHASE_NODES) / PHASE_NODES
    for s in range(n_seg):
        grid[:, HEAD + PER_SEGMENT * s + 7] = phases
    return grid


def _phase_mean_estimate(scenario: Scenario) -> np.ndarray:
    """The reduction of the start-angle-averaged noise-free means at the nominal draws (39,)."""
    means = noise_free_segment_means(scenario, _phase_grid_draws(scenario)).mean(axis=0)
    return reduce(means, scenario.schedule, scenario.reduction.reference_gravity,
                  scenario.reduction.omega_squared_sign)


def systematic_effects(scenario: Scenario) -> tuple[np.ndarray, list[tuple[str, np.ndarray, str]]]:
    """The expected error of every parameter and its split into uncorrected systematic effects.

    Each effect's bias is the estimate with the effect minus the estimate without it (all else as
    in the scenario), both from the noise-free segment means at the nominal draws averaged over the
    table start angle.

    Returns
    -------
    total : ndarray (39,)
        ``y``: estimate − truth at the expectation of the inputs, SI.
    effects : list of (name, bias (39,), note)
        Nonzero effects only; an ``"interaction of the effects"`` line closes the sum when needed.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.scenario.Scenario")
    full = _phase_mean_estimate(scenario)
    total = full - scenario.truth_nominal
    e = scenario.effects
    zero3 = np.zeros(3)
    candidates = []
    if scenario.environment.earth_rate:
        candidates.append(("Earth rate", dataclasses.replace(
            scenario, environment=dataclasses.replace(scenario.environment, earth_rate=False)),
            "not modelled by eq. (1); its vertical component flips with the up/down pairs (digest §1.4)"))
    if np.any(e.accel_lever_arm != 0):
        candidates.append(("accelerometer lever arm", dataclasses.replace(
            scenario, effects=dataclasses.replace(e, accel_lever_arm=np.zeros((3, 3)))),
            "centripetal r·ω² follows the same ω² law as P (digest §1.4)"))
    if scenario.reduction.reference_gravity != scenario.environment.gravity:
        candidates.append(("reference gravity", dataclasses.replace(
            scenario,
            reduction=dataclasses.replace(scenario.reduction, reference_gravity=scenario.environment.gravity)),
            f"matrix A uses g = {scenario.reduction.reference_gravity:.6f} m/s^2, local g = "
            f"{scenario.environment.gravity:.6f} m/s^2"))
    if scenario.reduction.omega_squared_sign != "model":
        candidates.append(("omega-squared sign as printed", dataclasses.replace(
            scenario, reduction=dataclasses.replace(scenario.reduction, omega_squared_sign="model")),
            "eq. (12)-(13) as printed return −p (digest §1.4)"))
    temperature = ("gyro_bias_temperature_coefficient", "gyro_scale_temperature_coefficient",
                   "accel_bias_temperature_coefficient", "accel_scale_temperature_coefficient")
    if any(np.any(getattr(e, name) != 0) for name in temperature):
        candidates.append(("temperature", dataclasses.replace(
            scenario, effects=dataclasses.replace(e, **{name: zero3 for name in temperature})),
            "temperature coefficients with the schedule's temperatures (not in eq. (1)/(2))"))
    others = {"gyro_nonlinearity_quadratic": zero3, "gyro_nonlinearity_cubic": zero3, "gyro_asymmetry": zero3,
              "accel_second_order": zero3, "gyro_g2_sensitivity": np.zeros((3, 3))}
    if any(np.any(getattr(e, name) != 0) for name in others):
        candidates.append(("sensor effects outside eq. (1)/(2)", dataclasses.replace(
            scenario, effects=dataclasses.replace(e, **others)),
            "nonlinearity, asymmetry, g² sensitivity, accelerometer second order"))
    effects = []
    explained = np.zeros(N_PARAMETERS)
    for name, without, note in candidates:
        bias = full - _phase_mean_estimate(without)
        explained += bias
        effects.append((name, bias, note))
    rest = total - explained
    scale = np.maximum(np.abs(scenario.truth_nominal), 1.0) * 1e-12
    if np.any(np.abs(rest) > scale):
        effects.append(("interaction of the effects", rest, "the effects above act together (not additive)"))
    return total, effects


# ----------------------------------------------------------------------------- the evaluation


@dataclass
class _Line:
    """A budget line for all parameters at once: columns of signed contributions (39, K) or a covariance."""

    name: str
    category: str
    evaluation: str
    distribution: str
    u: np.ndarray  # (K,) standard uncertainty of each component, or empty for covariance lines
    input_unit: str
    columns: np.ndarray | None = None  # (39, K): c_i·u_i
    covariance: np.ndarray | None = None  # (39, 39) for lines that are not a sum of independent columns
    dof: np.ndarray | None = None  # (K,) for type A lines
    note: str = ""
    linearised: bool = True
    second_order: np.ndarray | None = None  # (39,) largest ½|c_ii|u² of the line
    mixed_units: bool = False  # components in different units: no single u(x_i) or c_i to show
    line_dof: float = math.inf  # ν of a covariance line taken as one input (G.4.2 for type B)

    def variance(self) -> np.ndarray:
        if self.columns is not None:
            return np.sum(self.columns**2, axis=1)
        return np.clip(np.diag(self.covariance), 0.0, None)

    def cov(self) -> np.ndarray:
        if self.columns is not None:
            return self.columns @ self.columns.T
        return self.covariance


def _distribution_text(error: ErrorDistribution, unit: str) -> str:
    shown = "" if unit == "1" else f" {unit}"
    if error.kind == "uniform":
        return f"rectangular ±{error.scale:.4g}{shown}"
    return f"normal, σ = {error.scale:.4g}{shown}"


def _table_groups(scenario: Scenario) -> list[tuple[str, ErrorDistribution, list[int], str]]:
    """(name, distribution, draws indices, unit) of each table/fixture error group.

    Indices into the draws vector, layout of :mod:`plansim.simulate.physics`.
    """
    t = scenario.turntable
    segments = scenario.schedule.segments
    n_seg = len(segments)
    accuracy = [HEAD + PER_SEGMENT * s + 2 * axis for s in range(n_seg) for axis in range(3)]
    repeatability = [HEAD + PER_SEGMENT * s + 2 * axis + 1 for s in range(n_seg) for axis in range(3)]
    axes = sorted({"xyz".index(s.rate_axis[1]) for s in segments if s.rate != 0.0})
    perpendicularity = [45 + 2 * a + k for a in axes for k in range(2)]
    per_point = [HEAD + PER_SEGMENT * s + 6 for s, seg in enumerate(segments) if seg.rate != 0.0]
    rotating = bool(per_point)
    groups = [
        ("position accuracy", t.position_accuracy, accuracy, "rad"),
        ("position repeatability", t.position_repeatability, repeatability, "rad"),
        ("axis perpendicularity", t.axis_perpendicularity, perpendicularity, "rad"),
        ("platform tilt", t.platform_tilt, [42, 43], "rad"),
        ("fixture perpendicularity", t.fixture_perpendicularity, [39, 40, 41], "rad"),
        ("rate error, systematic", t.rate_error_systematic, [44] if rotating else [], "1"),
        ("rate error, per point", t.rate_error_per_point, per_point, "1"),
    ]
    return [g for g in groups if g[1].standard_uncertainty > 0 and g[2]]


def _finite_differences(scenario: Scenario, indices: np.ndarray, steps: np.ndarray
                        ) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivatives (K, S, 6) of the noise-free segment means w.r.t. draws components.

    Central differences with step ``steps[k]`` around the nominal draws, averaged over the table
    start angle (:data:`PHASE_NODES` angles): the derivatives of the expected means.
    """
    grid = _phase_grid_draws(scenario)  # (J, D)
    n_in = len(indices)
    n_seg = len(scenario.schedule)
    if n_in == 0:
        return np.zeros((0, n_seg, 6)), np.zeros((0, n_seg, 6))
    plus = np.repeat(grid[None, :, :], n_in, axis=0)  # (K, J, D)
    minus = plus.copy()
    k = np.arange(n_in)
    plus[k, :, indices] += steps[:, None]
    minus[k, :, indices] -= steps[:, None]
    d = grid.shape[1]
    mean_plus = noise_free_segment_means(scenario, plus.reshape(-1, d)).reshape(n_in, PHASE_NODES, n_seg, 6).mean(1)
    mean_minus = noise_free_segment_means(scenario, minus.reshape(-1, d)).reshape(n_in, PHASE_NODES, n_seg, 6).mean(1)
    centre = noise_free_segment_means(scenario, grid).mean(axis=0)
    first = (mean_plus - mean_minus) / (2.0 * steps[:, None, None])
    second = (mean_plus + mean_minus - 2.0 * centre[None]) / steps[:, None, None] ** 2
    return first, second


def _series_sum(fraction: np.ndarray, damping: np.ndarray) -> np.ndarray:
    """``Σ_{k≥1} cos(2πk·f) exp(−2π²k²τ²)/k²`` elementwise for ``f`` = *fraction*, ``τ²`` = *damping*.

    Summed term by term until the damping makes the terms negligible (exp(−46) ≈ 1e-20); where that
    would need more than :data:`_MAX_TERMS` terms the undamped sum ``π²(x² − x + 1/6)``
    (x = f mod 1, the Bernoulli polynomial B₂) is used, whose error is O(τ).
    """
    fraction = np.asarray(fraction, dtype=float)
    damping = np.asarray(damping, dtype=float)
    x = fraction - np.floor(fraction)
    undamped = np.pi**2 * (x**2 - x + 1.0 / 6.0)
    tau = np.sqrt(np.maximum(damping, 0.0))
    needed = np.where(tau > 0, np.ceil(np.sqrt(46.0 / (2.0 * np.pi**2)) / np.maximum(tau, 1e-300)), np.inf)
    series = needed <= _MAX_TERMS
    out = undamped.copy()
    if np.any(series):
        terms = int(np.max(needed[series]))
        xs, ds = x[series], damping[series]
        acc = np.zeros_like(xs)
        for k in range(1, terms + 1):
            acc += np.cos(2.0 * np.pi * k * xs) * np.exp(-2.0 * np.pi**2 * k**2 * ds) / k**2
        out[series] = acc
    return out


#: Most terms of the quantisation series summed term by term (beyond: the undamped closed form).
_MAX_TERMS = 2000


def quantisation_covariance(step: float, means: np.ndarray, sigma: np.ndarray, samples: np.ndarray,
                            offset_covariance: np.ndarray | None = None) -> np.ndarray:
    """Covariance (S, S) of the quantisation errors of the segment means of one channel.

    Appendix A's rectangular model per reading, with the correlation GUM 5.2 requires between
    segments of one channel: they share the quantiser and the unknown offset of the channel's
    output (uniform modulo q, the state of knowledge behind the rectangular model), and differ by
    the nominal output differences ``Δ_st = means[t] − means[s]``, themselves uncertain with
    variance ``Var(Δ_st)`` from *offset_covariance* (table errors, unit spread, drift). With the
    bias of a noisy quantiser ``b(μ) = Σ_k (−1)^{k+1} q/(πk) γ_k(σ) sin(2πkμ/q)``
    (:func:`quantisation_variance`) the covariance is, exactly for jointly normal offsets,

        Cov(b_s, b_t) = (q²/2π²) Σ_k cos(2πkΔ_st/q) exp(−2π²k²(σ_s² + σ_t² + Var Δ_st)/q²) / k²,

    and the diagonal adds the part the noise averages, ``(q²/12 − B_s)/n_s``. Two segments reading
    the same code without dither are fully correlated; segments far apart in output, or with
    dither, are independent (Appendix A's assumption).

    Parameters
    ----------
    step : float
        Quantisation step q (> 0).
    means : (S,) array
        Nominal (noise-free) segment means of the channel.
    sigma : (S,) array
        White noise σ of one sample at the quantiser input (rate jitter included).
    samples : (S,) array
        Samples per segment.
    offset_covariance : (S, S) array, optional
        Covariance of the segment means' deviations from nominal other than white noise.

    Returns
    -------
    (S, S) ndarray
    """
    if not (math.isfinite(step) and step > 0):
        raise ValueError(f"step = {step!r}: the quantisation step must be finite and > 0")
    means = np.asarray(means, dtype=float)
    sigma = np.asarray(sigma, dtype=float)
    samples = np.asarray(samples, dtype=float)
    n_seg = means.shape[0]
    if sigma.shape != (n_seg,) or samples.shape != (n_seg,):
        raise ValueError(f"means, sigma, samples: shapes {means.shape}, {sigma.shape}, {samples.shape}; "
                         "expected one value per segment")
    if offset_covariance is None:
        var_delta = np.zeros((n_seg, n_seg))
    else:
        g = np.asarray(offset_covariance, dtype=float)
        var_delta = np.maximum(np.diag(g)[:, None] + np.diag(g)[None, :] - 2.0 * g, 0.0)
    fraction = (means[None, :] - means[:, None]) / step
    damping = (sigma[:, None] ** 2 + sigma[None, :] ** 2 + var_delta) / step**2
    cov = step**2 / (2.0 * np.pi**2) * _series_sum(fraction, damping)
    full = step**2 / 12.0
    bias = np.clip(np.diag(cov).copy(), 0.0, full)
    cov[np.diag_indices(n_seg)] = bias + (full - bias) / samples
    return cov


def _rate_derivatives(scenario: Scenario) -> np.ndarray:
    """(S, 6): ``rate · ∂(segment mean)/∂(rate)`` of each rotating segment, averaged over the start angle.

    The response of the outputs to the per-sample rate jitter of the table: the gyro input ω·u
    (and with it P·ω²) follows the rate, the centripetal term of the lever arm does not (the
    simulator jitters the gyro input only), so the derivative is taken with the lever arm removed,
    by central differences of the noise-free means in the relative rate error of each point.
    """
    without_lever = dataclasses.replace(
        scenario, effects=dataclasses.replace(scenario.effects, accel_lever_arm=np.zeros((3, 3))))
    segments = scenario.schedule.segments
    rotating = [s for s, seg in enumerate(segments) if seg.rate != 0.0]
    out = np.zeros((len(segments), 6))
    if not rotating:
        return out
    indices = np.array([HEAD + PER_SEGMENT * s + 6 for s in rotating], dtype=np.int64)
    first, _ = _finite_differences(without_lever, indices, np.full(len(rotating), _RATE_STEP))
    for k, s in enumerate(rotating):
        out[s] = first[k, s]
    return out


#: Relative step of the table rate for :func:`_rate_derivatives`.
_RATE_STEP = 1e-6


def _model_lines(scenario: Scenario, matrix: np.ndarray, quantisation_correlation: bool) -> list[_Line]:
    """Every budget line, for all parameters at once."""
    lines: list[_Line] = []
    segments = scenario.schedule.segments
    n_seg = len(segments)
    samples = np.array([s.samples for s in segments], dtype=float)
    durations = np.array([s.samples / s.sample_rate for s in segments])
    dts = np.array([1.0 / s.sample_rate for s in segments])
    args = kernel_arguments(scenario)
    noise = args["noise"]
    offsets = [np.zeros((n_seg, n_seg)) for _ in range(6)]  # per channel: covariance of the means' offsets

    # table and fixture errors: finite differences of the noise-free means
    groups = _table_groups(scenario)
    if groups:
        indices = np.concatenate([np.array(g[2], dtype=np.int64) for g in groups])
        steps = np.concatenate([np.full(len(g[2]), g[1].standard_uncertainty) for g in groups])
        first, second = _finite_differences(scenario, indices, steps)
        start = 0
        for name, error, idx, unit in groups:
            stop = start + len(idx)
            u = np.full(len(idx), error.standard_uncertainty)
            d_means = first[start:stop] * u[:, None, None]  # (K, S, 6)
            for c in range(6):
                offsets[c] += d_means[:, :, c].T @ d_means[:, :, c]
            lines.append(_Line(
                name=name, category="table", evaluation="B", distribution=_distribution_text(error, unit),
                u=u, input_unit=unit, columns=np.einsum("psc,ksc->pk", matrix, d_means),
                note="c by central differences of the noise-free segment means, step u(x)",
                second_order=np.max(0.5 * np.abs(np.einsum("psc,ksc->pk", matrix, second[start:stop]))
                                    * u[None, :] ** 2, axis=1)))
            start = stop

    # table start angle of the rotating segments: exact variance over the angle
    rotating = [s for s, seg in enumerate(segments) if seg.rate != 0.0]
    nominal = noise_free_segment_means(scenario, _phase_grid_draws(scenario))  # (J, S, 6)
    if rotating:
        centre = nominal.mean(axis=0)
        deviation = nominal - centre
        # below 64 ulp of the mean the deviation is rounding, not a start-angle effect
        deviation[np.abs(deviation) <= 64 * np.finfo(float).eps * np.abs(centre)[None]] = 0.0
        cov = np.zeros((N_PARAMETERS, N_PARAMETERS))
        for s in rotating:
            d = np.einsum("pc,jc->jp", matrix[:, s, :], deviation[:, s, :])  # (J, 39)
            cov += d.T @ d / PHASE_NODES
            for c in range(6):
                offsets[c][s, s] += float(np.mean(deviation[:, s, c] ** 2))
        if np.any(np.diag(cov) > 0):
            lines.append(_Line(
                name="table start angle", category="table", evaluation="B",
                distribution="uniform on [0, 2π) per rotating segment",
                u=np.full(len(rotating), math.pi / math.sqrt(3)),
                input_unit="rad", covariance=cov, linearised=False,
                note=f"exact variance over {PHASE_NODES} start angles (segments not whole turns)"))
    nominal = nominal.mean(axis=0)  # (S, 6): expected noise-free means

    # the unit under calibration: dependence of the error on the true parameters
    spread = np.asarray(scenario.truth_spread, dtype=float)
    idx = np.flatnonzero(spread > 0)
    if idx.size:
        first, second = _finite_differences(scenario, idx, spread[idx])
        d_means = first * spread[idx][:, None, None]
        for c in range(6):
            offsets[c] += d_means[:, :, c].T @ d_means[:, :, c]
        columns = np.einsum("psc,ksc->pk", matrix, d_means)
        columns[idx, np.arange(idx.size)] -= spread[idx]  # E = Ŷ − Y
        lines.append(_Line(
            name="unit-to-unit spread", category="unit", evaluation="B", distribution="normal (mimu.truth_spread)",
            u=spread[idx], input_unit="SI of each parameter", columns=columns, mixed_units=True,
            note="∂E/∂Y = R·∂m/∂Y − 1: the error's dependence on the true value",
            second_order=np.max(0.5 * np.abs(np.einsum("psc,ksc->pk", matrix, second)) * spread[idx][None, :] ** 2,
                                axis=1)))

    # white noise of the segment means (type A, ν = n − 1)
    for label, channels in (("white noise, gyros", range(3)), ("white noise, accelerometers", range(3, 6))):
        u = np.array([[noise[c, 0] / math.sqrt(durations[s]) for c in channels] for s in range(n_seg)])
        if not np.any(u > 0):
            continue
        columns = np.stack([matrix[:, s, c] * u[s, i] for s in range(n_seg) for i, c in enumerate(channels)], axis=1)
        dof = np.repeat(samples - 1.0, len(channels))
        dof = np.where(dof > 0, dof, np.inf)
        unit = "rad/s" if label.endswith("gyros") else "m/s^2"
        lines.append(_Line(
            name=label, category="repeatability", evaluation="A", distribution="normal, N/√T per segment mean",
            u=u.ravel(), input_unit=unit, columns=columns, dof=dof,
            note="u = N/√T (random-walk coefficient N, dwell T); ν = n − 1 samples"))

    # drift: exact covariance of the segment means
    drift = drift_covariance(scenario)
    for c in range(6):
        offsets[c] += drift[c]
    for label, channels in (("drift, gyros", range(3)), ("drift, accelerometers", range(3, 6))):
        cov = np.zeros((N_PARAMETERS, N_PARAMETERS))
        for c in channels:
            if np.any(drift[c] != 0):
                cov += matrix[:, :, c] @ drift[c] @ matrix[:, :, c].T
        if np.any(np.diag(cov) > 0):
            lines.append(_Line(
                name=label, category="repeatability", evaluation="B",
                distribution="Gauss–Markov / random walk (Allan coefficients)",
                u=np.sqrt(np.array([drift[c].diagonal().mean() for c in channels])),
                input_unit="rad/s" if label.endswith("gyros") else "m/s^2", covariance=cov, linearised=True,
                note="covariance of the segment means derived from the drift model (GUM 5.2.2)"))

    # rate smoothness: jitter of the table rate, common to the channels of a segment
    smoothness = scenario.turntable.rate_smoothness
    jitter = np.zeros((n_seg, 6))
    if smoothness > 0 and rotating:
        derivative = _rate_derivatives(scenario)
        jitter = smoothness * derivative
        u = np.array([smoothness / math.sqrt(samples[s]) for s in rotating])
        columns = np.stack([matrix[:, s, :] @ derivative[s] * u[i] for i, s in enumerate(rotating)], axis=1)
        lines.append(_Line(
            name="rate smoothness", category="table", evaluation="B", distribution="normal, per sample",
            u=u, input_unit="1", columns=columns,
            note="segment mean of the per-sample relative rate jitter, through ∂(outputs)/∂(rate)"))

    # quantisation (Appendix A's rectangular model, with the averaging the noise provides)
    a = scenario.acquisition
    if a.bits:
        for label, channels, step in (("quantisation, gyros", range(3), a.gyro_step),
                                      ("quantisation, accelerometers", range(3, 6), a.accel_step)):
            cov = np.zeros((N_PARAMETERS, N_PARAMETERS))
            fractions, u_means = [], []
            for c in channels:
                sigma = np.sqrt(noise[c, 0] ** 2 / dts + jitter[:, c] ** 2)
                if quantisation_correlation:
                    q_cov = quantisation_covariance(step, nominal[:, c], sigma, samples, offsets[c])
                else:
                    q_cov = np.diag([quantisation_variance(step, float(sigma[s]), int(samples[s]))[0]
                                     for s in range(n_seg)])
                cov += matrix[:, :, c] @ q_cov @ matrix[:, :, c].T
                fractions.extend(quantisation_variance(step, float(sigma[s]), int(samples[s]))[1]
                                 for s in range(n_seg))
                u_means.extend(np.sqrt(np.diag(q_cov)))
            worst = max(fractions)
            regime = ("no dither: rectangular ±q/2 per segment mean" if worst > 1.0 - 1e-6 else
                      "dithered: q²/12 per sample, averaged" if worst < 1e-6 else
                      f"partly dithered: up to {worst:.2g} of q²/12 not averaged by the noise")
            correlation = ("segments correlated through the shared quantiser offset" if quantisation_correlation
                           else "segment means independent (Appendix A)")
            lines.append(_Line(
                name=label, category="acquisition", evaluation="B",
                distribution=f"rectangular, q = {step:.4g}; {regime}",
                u=np.asarray(u_means), input_unit="rad/s" if label.endswith("gyros") else "m/s^2", covariance=cov,
                note=f"Appendix A eq. (A.3); {correlation}"))
    return lines


def _appendix_view(budget: AppendixABudget, name: str, scenario: Scenario, per_category: tuple[float, float, float],
                   uc: float, U: float) -> AppendixAView:
    unit = float(reading_unit_in_si(budget, name, scenario))
    same = math.sqrt(sum(c.gum_standard_uncertainty**2 for c in budget.components))
    printed = tuple(budget.component(sym).printed_value for sym in ("u1", "u2", "u3"))
    return AppendixAView(
        item=budget.item, reading_unit_si=unit, printed_u=printed,
        printed_uc=budget.printed_combined_standard_uncertainty, printed_U=budget.printed_expanded_uncertainty,
        same_inputs_gum_uc=same, same_inputs_gum_U=budget.coverage_factor * same,
        plansim_u=tuple(x / unit for x in per_category), plansim_uc=uc / unit, plansim_U95=U / unit)


def evaluate_gum(scenario: Scenario, coverage_probability: float = DEFAULT_COVERAGE_PROBABILITY,
                 quantisation_correlation: bool = True,
                 relative_uncertainty_of_u: Mapping[str, float] | None = None) -> GumEvaluation:
    """GUM budgets of every JJF 2003 parameter for *scenario* (module docstring).

    Parameters
    ----------
    scenario : Scenario
        The scenario (schedule, table, noise, acquisition, reduction).
    coverage_probability : float
        ``p`` of the expanded uncertainties (default 0.95).
    quantisation_correlation : bool
        Correlate the quantisation errors of the segments of a channel through the quantiser's
        shared offset (:func:`quantisation_covariance`, default); ``False`` treats every segment
        mean as an independent rectangular input, as Appendix A treats its readings.
    relative_uncertainty_of_u : mapping of input name -> float, optional
        For type B inputs whose standard uncertainty is itself uncertain: the relative
        uncertainty ``Δu/u`` the user states, giving ``ν = ½ (Δu/u)⁻²`` (GUM G.4.2, eq. (G.3)) for
        each component of that budget line (e.g. ``{"rate error, systematic": 0.25}`` gives ν = 8).
        Inputs not named keep ``ν = ∞`` (a ± limit taken as exactly known).

    Returns
    -------
    GumEvaluation
        Per-parameter budgets (inputs, ``u_c``, ``ν_eff``, ``k``, ``U``, uncorrected systematic
        effects, the Appendix A figure) and the covariance of the 39 errors.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.scenario.Scenario")
    coverage_factor(math.inf, coverage_probability)  # validates p
    matrix = estimator_matrix(scenario)
    if not isinstance(quantisation_correlation, bool):
        raise TypeError(f"quantisation_correlation = {quantisation_correlation!r}: expected True or False")
    lines = _model_lines(scenario, matrix, quantisation_correlation)
    if relative_uncertainty_of_u:
        if not isinstance(relative_uncertainty_of_u, Mapping):
            raise TypeError(f"relative_uncertainty_of_u = {relative_uncertainty_of_u!r}: expected a mapping of "
                            "budget-line name -> relative uncertainty of its u")
        by_name = {line.name: line for line in lines}
        for name, r in relative_uncertainty_of_u.items():
            if name not in by_name:
                raise ValueError(f"relative_uncertainty_of_u: no input {name!r} in this scenario's budget; "
                                 f"inputs: {', '.join(map(repr, by_name))}")
            if isinstance(r, bool) or not isinstance(r, (int, float)) or not (math.isfinite(r) and r > 0):
                raise ValueError(f"relative_uncertainty_of_u[{name!r}] = {r!r}: must be a number > 0")
            line = by_name[name]
            if line.evaluation != "B":
                raise ValueError(f"relative_uncertainty_of_u[{name!r}]: a type A input has its degrees of freedom "
                                 "from its sample count (GUM G.3.3); G.4.2 applies to type B inputs")
            nu = 0.5 / r**2
            if line.columns is not None:
                line.dof = np.full(line.columns.shape[1], nu)
            else:
                line.line_dof = nu
    total, effects = systematic_effects(scenario)
    covariance = np.zeros((N_PARAMETERS, N_PARAMETERS))
    for line in lines:
        covariance += line.cov()
    covariance = 0.5 * (covariance + covariance.T)
    appendix = {name: b for b in APPENDIX_A for name in b.parameters}

    budgets = []
    variances = [line.variance() for line in lines]
    for p, spec in enumerate(PARAMETERS):
        entries = []
        ws_terms = []  # (contribution, dof) of every independent component with finite ν
        second = 0.0
        uc = math.sqrt(max(float(covariance[p, p]), 0.0))
        for line, variance in zip(lines, variances):
            contribution = math.sqrt(float(variance[p]))
            if contribution <= NEGLIGIBLE * uc or contribution == 0.0:
                continue  # below the numerical noise of the finite differences
            if line.columns is not None and line.dof is not None:
                finite = np.isfinite(line.dof)
                ws_terms.extend(zip(np.abs(line.columns[p, finite]), line.dof[finite]))
                group_dof = welch_satterthwaite(line.columns[p], line.dof)
            else:
                group_dof = line.line_dof
                if math.isfinite(group_dof):
                    ws_terms.append((contribution, group_dof))
            if line.second_order is not None:
                second = max(second, float(line.second_order[p]))
            u_rms = float(np.sqrt(np.mean(line.u**2))) if line.u.size else math.nan
            if line.mixed_units:
                u_rms = sensitivity = math.nan
            elif line.columns is not None and np.count_nonzero(line.columns[p]) == 1:
                k = int(np.flatnonzero(line.columns[p])[0])
                u_rms = float(line.u[k])
                sensitivity = float(line.columns[p, k] / line.u[k])
            elif line.linearised and u_rms > 0:
                sensitivity = contribution / u_rms
            else:
                sensitivity = math.nan
            entries.append(InputContribution(
                name=line.name, category=line.category, evaluation=line.evaluation,
                distribution=line.distribution,
                standard_uncertainty=u_rms if line.linearised else math.nan,
                input_unit=line.input_unit, sensitivity=sensitivity, contribution=contribution,
                dof=group_dof, components=int(line.u.size), note=line.note))
        entries.sort(key=lambda e: -e.contribution)
        if ws_terms and uc > 0:
            c, nu = np.array(ws_terms).T
            denominator = float(np.sum(c**4 / nu))
            dof = uc**4 / denominator if denominator > 0 else math.inf
        else:
            dof = math.inf
        k = coverage_factor(dof, coverage_probability)
        U = k * uc
        found = tuple(SystematicEffect(name, float(bias[p]), note) for name, bias, note in effects if bias[p] != 0.0)
        view = None
        if spec.name in appendix:
            budget = appendix[spec.name]
            per_category = tuple(math.sqrt(sum(e.contribution**2 for e in entries if e.category == cat))
                                 for cat in ("table", "acquisition", "repeatability"))
            view = _appendix_view(budget, spec.name, scenario, per_category, uc, U)
        budgets.append(ParameterBudget(
            name=spec.name, unit=spec.si_unit, truth=float(scenario.truth_nominal[p]), estimate=float(total[p]),
            inputs=tuple(entries), combined_standard_uncertainty=uc, effective_dof=dof, coverage_factor=k,
            expanded_uncertainty=U, coverage_probability=coverage_probability, systematic_effects=found,
            largest_second_order=second, appendix_a=view))
    return GumEvaluation(scenario=scenario.name, budgets=tuple(budgets), covariance=covariance,
                         coverage_probability=coverage_probability)
