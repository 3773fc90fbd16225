"""Validation of a calibration's uncertainty: GUM budget, adaptive Monte Carlo, JCGM 101 §8, coverage of the truth.

:func:`validate` runs, for one scenario and a ``simulate(trials, seed)`` callable of its calibration,

1. the GUM budgets of all 39 parameters from the schedule (:func:`plansim.uncertainty.gum.evaluate_gum`);
2. the adaptive Monte Carlo method of JCGM 101 7.9.4 on the simulated calibration
   (:func:`plansim.uncertainty.monte_carlo.calibration_monte_carlo`), run to the numerical
   tolerance JCGM 101 8.2 asks of a validation run — a fraction (default 1/5) of ``δ`` of the
   GUM ``u_c``;
3. the validation of the GUM framework, JCGM 101 8.1: ``d_low = |y − U_p − y_low|``,
   ``d_high = |y + U_p − y_high|`` against ``δ`` → "validated: yes/no", with the reasons read off
   the numbers when it fails (a bias, a wrong ``u``, a non-Gaussian shape and the input that
   dominates it);
4. the coverage of the truth (the simulator knows it): the fraction of trials whose interval
   ``estimate ± U`` contains the true value, for plansim's GUM ``U95`` and for each *claimed* ``U``
   (default: the Appendix A budgets as printed, :mod:`plansim.uncertainty.claims`), with the
   verdict of :func:`plansim.uncertainty.metrology.coverage_verdict`;
5. for Appendix A items A.1–A.5: the printed, recomputed and GUM-recombined budgets (the slips of
   :func:`plansim.uncertainty.appendix_a.printed_arithmetic_slips`) next to what this schedule achieves,
   and — where the item's claim is a bare number (Appendix A as printed, or a claims file's
   ``[items."A.x"]``) — its coverage and verdict under every reading of the item's unit
   (``AppendixABudget.readings``), with whether the verdict holds under every reading;
6. JCGM 102: the correlation matrix of the estimated parameters and the joint 95 % region of the
   3×3 Kg against the box of its nine marginal ``k = 2`` intervals.

The runner supplies the simulate callable (:func:`plansim.runner.validate`); the text and JSON of
the report are :mod:`plansim.report.validation`.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, parameter
from plansim.uncertainty.appendix_a import (
    APPENDIX_A,
    printed_arithmetic_slips,
    reading_unit_description,
    reading_unit_in_si,
)
from plansim.uncertainty.appendix_a_comparison import HOLDS_UNDER_EVERY_READING, ReadingComparison, reading_dependence
from plansim.uncertainty.budget import GumEvaluation, ParameterBudget
from plansim.uncertainty.claims import Claim, appendix_a_claims
from plansim.uncertainty.gum import evaluate_gum
from plansim.uncertainty.metrology.coverage import coverage_against_truth, coverage_verdict
from plansim.uncertainty.metrology.monte_carlo import (
    DEFAULT_DIGITS,
    DEFAULT_TRIALS_PER_BLOCK,
    Simulate,
    numerical_tolerance,
)
from plansim.uncertainty.metrology.several_outputs import JointRegionCheck, correlation_matrix
from plansim.uncertainty.metrology.validation import validate_gum
from plansim.uncertainty.monte_carlo import (
    KG_PARAMETERS,
    CalibrationMonteCarlo,
    calibration_monte_carlo,
    joint_region_check,
)

__all__ = [
    "DEFAULT_MAX_TRIALS",
    "DEFAULT_TOLERANCE_FRACTION",
    "AppendixItemCheck",
    "ParameterValidation",
    "ValidationReport",
    "validate",
]

#: JCGM 101 8.2: a Monte Carlo run used to validate the GUM is taken to a tolerance of δ/5.
DEFAULT_TOLERANCE_FRACTION = 0.2
#: Upper limit of the adaptive procedure's trials (memory: 39 doubles per trial).
DEFAULT_MAX_TRIALS = 1_000_000


# ----------------------------------------------------------------------------- results


@dataclass(frozen=True)
class ParameterValidation:
    """GUM, MCM, the JCGM 101 §8 validation and the coverage of the truth for one parameter (SI).

    The output quantity is the parameter's error ``E = Ŷ − Y``; ``gum_y`` is its GUM estimate
    (the uncorrected systematic effects), ``mcm_y`` the Monte Carlo mean.
    """

    name: str
    unit: str
    gum_y: float
    gum_u: float
    gum_dof: float
    gum_k: float
    gum_U95: float
    mcm_y: float
    mcm_u: float
    mcm_low: float
    mcm_high: float
    mcm_shortest_low: float
    mcm_shortest_high: float
    mcm_U95_about_truth: float
    delta: float
    d_low: float
    d_high: float
    validated: bool
    reasons: tuple[str, ...]
    coverage_gum: float
    claimed_U: float | None
    claim_source: str | None
    claim_probability: float | None
    coverage_claimed: float | None
    claim_factor: float | None
    claim_verdict: str | None
    dominant_inputs: tuple[str, ...]
    appendix_item: str | None

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["reasons"] = list(self.reasons)
        d["dominant_inputs"] = list(self.dominant_inputs)
        d["validated"] = bool(self.validated)
        for key, value in d.items():
            if isinstance(value, float) and math.isinf(value):
                d[key] = "inf"
        return d


@dataclass(frozen=True)
class AppendixItemCheck:
    """An Appendix A budget: as printed, recomputed, recombined by the GUM, and achieved by this schedule.

    All uncertainties in the item's primary reading unit (``reading_unit``). ``readings`` judges the
    claimed number in every reading of the item's unit (the first is the primary one, whose
    coverage and verdict are ``coverage`` and ``verdict``): ``budget_U_si`` is the claimed number in
    that reading converted to SI, ``mc_U95`` the Monte Carlo's ``|E|`` quantile at the claim's
    probability in the reading, and the verdict is :func:`plansim.uncertainty.metrology.coverage_verdict`'s.
    Empty when the claim states its unit (a claims file's ``[parameters.<name>]``): there is no
    reading to choose then.
    """

    item: str
    quantity: str
    reading_unit: str
    parameters: tuple[str, ...]
    printed_uc: float
    printed_U: float
    arithmetic_U: float
    same_inputs_gum_uc: float
    same_inputs_gum_U: float
    slips: tuple[str, ...]
    claimed_U: float
    gum_U95: tuple[float, ...]
    mcm_U95: tuple[float, ...]
    coverage: float
    verdict: str
    readings: tuple[ReadingComparison, ...] = ()

    @property
    def reading_dependence(self) -> str:
        """``"holds under every reading"`` or ``"depends on the reading"`` (one reading, or none: holds)."""
        return reading_dependence(r.verdict for r in self.readings) if self.readings else HOLDS_UNDER_EVERY_READING

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        for key in ("parameters", "slips", "gum_U95", "mcm_U95"):
            d[key] = list(d[key])
        d["readings"] = [r.as_dict() for r in self.readings]
        d["reading_dependence"] = self.reading_dependence
        return d


@dataclass(frozen=True)
class ValidationReport:
    """Everything :func:`validate` found (module docstring)."""

    scenario: str
    description: str
    gum: GumEvaluation
    mcm: CalibrationMonteCarlo
    parameters: tuple[ParameterValidation, ...]
    appendix_items: tuple[AppendixItemCheck, ...]
    joint: JointRegionCheck
    mcm_correlation: np.ndarray
    digits: int
    tolerance_fraction: float
    claims_source: str

    def parameter(self, name: str) -> ParameterValidation:
        """The validation of parameter *name*."""
        if name not in PARAMETER_INDEX:
            raise ValueError(f"unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        return self.parameters[PARAMETER_INDEX[name]]

    def item(self, item: str) -> AppendixItemCheck:
        """The check of Appendix A item *item* (``"A.1"`` … ``"A.5"``)."""
        for check in self.appendix_items:
            if check.item == item:
                return check
        raise ValueError(f"no Appendix A item {item!r} in this report; it has "
                         f"{', '.join(c.item for c in self.appendix_items) or 'none'}")


# ----------------------------------------------------------------------------- the computation


def _reasons(budget: ParameterBudget, mc: CalibrationMonteCarlo, i: int, delta: float,
             validated: bool) -> tuple[str, ...]:
    """Why the GUM interval differs from the MCM interval, read off the numbers (JCGM 101 5.7, 8)."""
    reasons = []
    u_g = budget.combined_standard_uncertainty
    u_m = float(mc.standard_uncertainty[i])
    y_m = float(mc.estimate[i])
    low, high = float(mc.low[i]), float(mc.high[i])
    scale = u_g if u_g > 0 else max(u_m, 1e-300)
    if not mc.tolerance_met()[i]:
        reasons.append(f"the Monte Carlo stopped before reaching its numerical tolerance for this output "
                       f"(2s = {2 * mc.block_sd[:, i].max():.3g}, target {mc.tolerance[i]:.3g}): the comparison "
                       "carries that much Monte Carlo noise")
    shift = y_m - budget.estimate
    if abs(shift) > delta:
        reasons.append(f"the MCM mean differs from the GUM estimate y by {shift / scale:+.3g} u_c: an offset the "
                       "linearised model does not give (nonlinearity, or an input whose effect is not zero-mean)")
    if abs(u_m - u_g) > delta:
        reasons.append(f"the MCM standard uncertainty is {u_m / scale:.3g} × the GUM u_c (inputs or their "
                       "correlation not as the GUM models them)")
    if u_m > 0:
        k_mc = 0.5 * (high - low) / u_m
        if abs(k_mc - budget.coverage_factor) * u_m > delta:
            shape = (f"the MCM {mc.coverage_probability:.0%} interval is ±{k_mc:.3g} u, "
                     f"the GUM's ±{budget.coverage_factor:.3g} u: "
                     f"the output is not Gaussian (excess kurtosis {mc.excess_kurtosis[i]:+.2f}, "
                     f"skewness {mc.skewness[i]:+.2f})")
            if budget.inputs and u_g > 0:
                top = budget.inputs[0]
                share = (top.contribution / u_g) ** 2
                if share > 0.5:
                    shape += f"; {top.name} dominates ({share:.0%} of u_c²; {top.distribution})"
            reasons.append(shape)
        asymmetry = (high - y_m) - (y_m - low)
        if abs(asymmetry) > delta:
            reasons.append(f"the MCM interval is asymmetric about its mean by {asymmetry / u_m:+.3g} u "
                           f"(skewness {mc.skewness[i]:+.2f})")
    if not validated and not reasons:
        reasons.append("d_low or d_high exceeds δ by less than the differences listed above resolve; "
                       "rerun with more trials or digits")
    return tuple(reasons)


def _dominant(budget: ParameterBudget, count: int = 2) -> tuple[str, ...]:
    uc = budget.combined_standard_uncertainty
    if uc <= 0:
        return ()
    return tuple(f"{line.name} ({(line.contribution / uc) ** 2:.0%})" for line in budget.inputs[:count])



def _parameter_validations(gum: GumEvaluation, mc: CalibrationMonteCarlo, claims: Mapping[str, Claim], digits: int,
                           coverage_probability: float) -> tuple[ParameterValidation, ...]:
    """JCGM 101 §8 and the coverage of the truth, per parameter."""
    outcome = validate_gum(gum.estimate, gum.expanded_uncertainty, gum.standard_uncertainty, mc.low, mc.high, digits)
    errors = mc.errors
    n = errors.shape[0]
    abs_errors = np.abs(errors)
    coverage_gum = coverage_against_truth(errors, gum.expanded_uncertainty)
    claimed = np.array([claims[name].expanded_uncertainty if name in claims else np.nan for name in PARAMETER_NAMES])
    coverage_claimed = coverage_against_truth(errors, claimed)
    results = []
    for i, (name, budget) in enumerate(zip(PARAMETER_NAMES, gum.budgets)):
        claim = claims.get(name)
        needed = float(np.quantile(abs_errors[:, i], coverage_probability))
        factor = verdict = probability = None
        covered = None
        if claim is not None:
            probability = claim.coverage_probability
            needed_claim = float(np.quantile(abs_errors[:, i], probability))
            covered = float(coverage_claimed[i])
            verdict, factor = coverage_verdict(covered, n, probability, claim.expanded_uncertainty, needed_claim)
        validated = bool(outcome.validated[i])
        results.append(ParameterValidation(
            name=name, unit=budget.unit, gum_y=budget.estimate, gum_u=budget.combined_standard_uncertainty,
            gum_dof=budget.effective_dof, gum_k=budget.coverage_factor, gum_U95=budget.expanded_uncertainty,
            mcm_y=float(mc.estimate[i]), mcm_u=float(mc.standard_uncertainty[i]), mcm_low=float(mc.low[i]),
            mcm_high=float(mc.high[i]), mcm_shortest_low=float(mc.shortest_low[i]),
            mcm_shortest_high=float(mc.shortest_high[i]), mcm_U95_about_truth=needed,
            delta=float(outcome.delta[i]), d_low=float(outcome.d_low[i]), d_high=float(outcome.d_high[i]),
            validated=validated, reasons=_reasons(budget, mc, i, float(outcome.delta[i]), validated),
            coverage_gum=float(coverage_gum[i]),
            claimed_U=None if claim is None else claim.expanded_uncertainty,
            claim_source=None if claim is None else claim.source, claim_probability=probability,
            coverage_claimed=covered, claim_factor=factor, claim_verdict=verdict,
            dominant_inputs=_dominant(budget),
            appendix_item=None if budget.appendix_a is None else budget.appendix_a.item))
    return tuple(results)


def _appendix_item_checks(scenario: Scenario, gum: GumEvaluation, errors: np.ndarray, claims: Mapping[str, Claim],
                          coverage_probability: float) -> tuple[AppendixItemCheck, ...]:
    """Each Appendix A item whose parameters carry one claim: printed, recombined, achieved (reading units)."""
    abs_errors = np.abs(errors)
    items = []
    for budget in APPENDIX_A:
        names = budget.parameters
        units = np.array([float(reading_unit_in_si(budget, nm, scenario)) for nm in names])
        idx = [PARAMETER_INDEX[nm] for nm in names]
        item_claims = [claims.get(nm) for nm in names]
        if any(c is None for c in item_claims):
            continue
        claimed_reading = np.array([c.expanded_uncertainty / u for c, u in zip(item_claims, units)])
        probabilities = {c.coverage_probability for c in item_claims}
        if np.ptp(claimed_reading) > 1e-9 * claimed_reading.max() or len(probabilities) != 1:
            continue  # the item's parameters carry different claims: judged per parameter only
        claimed_U = float(claimed_reading[0])
        pooled = np.concatenate([abs_errors[:, k] / u for k, u in zip(idx, units)])
        covered = float(np.mean(pooled <= claimed_U))
        probability = probabilities.pop()
        needed = float(np.quantile(pooled, probability))
        verdict, _ = coverage_verdict(covered, pooled.size, probability, claimed_U, needed)
        readings = ()
        if all(_claim_is_a_bare_number(c, budget.item) for c in item_claims):
            readings = tuple(_reading_check(budget, reading, scenario, abs_errors, idx, claimed_U, probability)
                             for reading in budget.readings)
        same = math.sqrt(sum(c.gum_standard_uncertainty**2 for c in budget.components))
        items.append(AppendixItemCheck(
            item=budget.item, quantity=budget.quantity, reading_unit=reading_unit_description(budget, scenario),
            parameters=tuple(names), printed_uc=budget.printed_combined_standard_uncertainty,
            printed_U=budget.printed_expanded_uncertainty, arithmetic_U=budget.recomputed_expanded_uncertainty(),
            same_inputs_gum_uc=same, same_inputs_gum_U=budget.coverage_factor * same,
            slips=printed_arithmetic_slips(budget), claimed_U=claimed_U,
            gum_U95=tuple(float(gum.budgets[k].expanded_uncertainty / u) for k, u in zip(idx, units)),
            mcm_U95=tuple(float(np.quantile(abs_errors[:, k], coverage_probability) / u) for k, u in zip(idx, units)),
            coverage=covered, verdict=verdict, readings=readings))
    return tuple(items)


def _claim_is_a_bare_number(claim: Claim, item: str) -> bool:
    """Whether *claim* is a number without a unit for *item*: Appendix A as printed
    (:func:`plansim.uncertainty.claims.appendix_a_claims`) or a claims file's ``[items."A.x"]``
    (:func:`plansim.uncertainty.claims.parse_claims`), as their ``source`` says."""
    return claim.source == f"Appendix A {item} (printed)" or f"[items.{item}]" in claim.source


def _reading_check(budget, reading, scenario: Scenario, abs_errors: np.ndarray, idx, claimed: float,
                   probability: float) -> ReadingComparison:
    """The claimed number *claimed* of one item read in *reading*: its coverage of the truth and the verdict."""
    units = np.array([float(reading_unit_in_si(budget, name, scenario, reading=reading)) for name in budget.parameters])
    pooled = np.concatenate([abs_errors[:, k] / u for k, u in zip(idx, units)])
    covered = float(np.mean(pooled <= claimed))
    needed = float(np.quantile(pooled, probability))
    verdict, factor = coverage_verdict(covered, pooled.size, probability, claimed, needed)
    return ReadingComparison(
        reading=reading.name, unit=reading_unit_description(budget, scenario, reading),
        si_unit=parameter(budget.parameters[0]).si_unit, unit_in_si=tuple(float(u) for u in units),
        budget_U_si=tuple(float(claimed * u) for u in units), coverage=covered, mc_U95=needed,
        mc_U95_si=needed * float(np.mean(units)), overstatement_factor=factor, verdict=verdict)


def validate(scenario: Scenario, simulate: Simulate, claims: Mapping[str, Claim] | None = None, *,
             digits: int = DEFAULT_DIGITS, trials_per_block: int = DEFAULT_TRIALS_PER_BLOCK,
             max_trials: int = DEFAULT_MAX_TRIALS, seed: int | None = None,
             tolerance_fraction: float = DEFAULT_TOLERANCE_FRACTION, path: str = "",
             coverage_probability: float = 0.95, joint_parameters=KG_PARAMETERS, monitor=None,
             progress: Callable[[int, int, float], None] | None = None) -> ValidationReport:
    """GUM budget, adaptive MCM, JCGM 101 §8 validation and coverage of the truth for a scenario.

    Parameters
    ----------
    scenario : Scenario
        The scenario whose calibration *simulate* simulates.
    simulate : callable
        ``simulate(trials, seed) -> (trials, 39)`` errors ``estimate − truth`` of the scenario's
        calibration (SI, order of :data:`plansim.model.parameters.PARAMETER_NAMES`).
    claims : mapping of parameter name -> Claim, optional
        Stated expanded uncertainties (:func:`plansim.uncertainty.claims.parse_claims`); default
        the Appendix A budgets (:func:`plansim.uncertainty.claims.appendix_a_claims`).
    digits : int
        ``n_dig`` of the numerical tolerances (JCGM 101 7.9.2).
    trials_per_block : int
        ``M`` of the adaptive procedure.
    max_trials : int
        Upper limit of the Monte Carlo trials.
    seed : int, optional
        Root seed (default the scenario's).
    tolerance_fraction : float
        The Monte Carlo runs until ``2s ≤ fraction·δ`` with ``δ`` of the GUM ``u_c`` (JCGM 101 8.2: 1/5).
    path : str
        Name of the simulation path *simulate* takes, for the report.
    coverage_probability : float
        ``p`` (0.95).
    joint_parameters : sequence of str
        Outputs checked jointly (JCGM 102; default the nine Kg).
    monitor : sequence of str, optional
        The outputs whose numerical tolerance stops the Monte Carlo (default every parameter whose
        GUM ``u_c`` is not 0: a tolerance ``δ = 0`` is never met by round-off; every output is
        validated, but those not monitored only to the accuracy the run happens to reach).
    progress : callable, optional
        ``progress(trials_done, blocks, worst)`` after each block
        (:func:`plansim.uncertainty.metrology.adaptive_monte_carlo`).

    Returns
    -------
    ValidationReport

    Raises
    ------
    TypeError
        *scenario* is not a Scenario, *simulate* is not callable, or *claims* is not a mapping of Claim.
    ValueError
        A bad tolerance fraction, or a bad argument of the adaptive procedure; a scenario without
        any uncertain input (every GUM ``u_c`` is 0: nothing to validate, before any simulation).
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario (plansim.runner.validate "
                        "also takes a built-in scenario name or a TOML path)")
    if not callable(simulate):
        raise TypeError(f"simulate = {simulate!r}: expected a callable simulate(trials, seed) -> (trials, 39) errors")
    if isinstance(tolerance_fraction, bool) or not isinstance(tolerance_fraction, (int, float)) \
            or not 0.0 < tolerance_fraction <= 1.0:
        raise ValueError(f"tolerance_fraction = {tolerance_fraction!r}: must lie in (0, 1] (JCGM 101 8.2 uses 1/5)")
    if claims is None:
        claims = appendix_a_claims(scenario)
        claims_source = "Appendix A of JJF 2003-2022 as printed (k = 2)"
    else:
        if not isinstance(claims, Mapping) or not all(isinstance(c, Claim) for c in claims.values()):
            raise TypeError("claims: expected a mapping of parameter name -> Claim (see parse_claims)")
        sources = sorted({c.source.split(" [")[0] for c in claims.values()})
        claims_source = ", ".join(sources)

    gum = evaluate_gum(scenario, coverage_probability)
    u_gum = gum.standard_uncertainty
    if not np.any(u_gum > 0):
        raise ValueError(f"scenario {scenario.name!r}: nothing to validate — none of its inputs is uncertain (no table "
                         "or fixture error, unit spread, noise, drift, quantisation or rate jitter), so the GUM "
                         "standard uncertainty of every parameter is 0 and a Monte Carlo would only see round-off; "
                         "'plansim run' shows its errors")
    if monitor is None:
        monitor = [name for name, u in zip(PARAMETER_NAMES, u_gum) if u > 0]
    delta_gum = np.asarray(numerical_tolerance(u_gum, digits))
    mc = calibration_monte_carlo(simulate, scenario, path=path, digits=digits, trials_per_block=trials_per_block,
                                 max_trials=max_trials, seed=seed, tolerance=tolerance_fraction * delta_gum,
                                 parameters=monitor, coverage_probability=coverage_probability, progress=progress)
    errors = mc.errors
    return ValidationReport(
        scenario=scenario.name, description=scenario.description, gum=gum, mcm=mc,
        parameters=_parameter_validations(gum, mc, claims, digits, coverage_probability),
        appendix_items=_appendix_item_checks(scenario, gum, errors, claims, coverage_probability),
        joint=joint_region_check(errors, joint_parameters, coverage_probability, gum_covariance=gum.covariance),
        mcm_correlation=correlation_matrix(errors), digits=int(digits), tolerance_fraction=float(tolerance_fraction),
        claims_source=claims_source)
