"""Validate a calibration's uncertainty claims: GUM budget, adaptive Monte Carlo, coverage of the truth.

:func:`validate` runs, for one scenario,

1. the GUM budgets of all 39 parameters from the schedule (:func:`plansim.uncertainty.gum.evaluate_gum`);
2. the adaptive Monte Carlo method of JCGM 101 7.9.4 on the simulated calibration
   (:func:`plansim.uncertainty.mcm.adaptive_monte_carlo`), run to the numerical tolerance JCGM 101
   8.2 asks of a validation run — a fraction (default 1/5) of ``δ`` of the GUM ``u_c``;
3. the validation of the GUM framework, JCGM 101 8.1: ``d_low = |y − U_p − y_low|``,
   ``d_high = |y + U_p − y_high|`` against ``δ`` → "validated: yes/no", with the reasons read off
   the numbers when it fails (a bias, a wrong ``u``, a non-Gaussian shape and the input that
   dominates it);
4. the coverage of the truth (the simulator knows it): the fraction of trials whose interval
   ``estimate ± U`` contains the true value, for plansim's GUM ``U95`` and for each *claimed* ``U``
   (default: the Appendix A budgets as printed), with a verdict and the factor by which a claim is
   over- or under-stated;
5. for Appendix A items A.1–A.5: the printed, recomputed and GUM-recombined budgets (the slips of
   digest §1.4 flagged) next to what this schedule achieves;
6. JCGM 102: the correlation matrix of the estimated parameters and the joint 95 % region of the
   3×3 Kg against the box of its nine marginal ``k = 2`` intervals.

:func:`add_validate_command` registers ``plansim validate``.

Claims file (TOML; ``U`` is an expanded uncertainty, ``k`` its coverage factor, default 2)::

    [items."A.2"]          # an Appendix A item, in the item's reading unit (docs/appendix-a.md)
    U = 5.36e-4
    k = 2

    [parameters.Bgx]       # one parameter, with a unit of its kind
    U = "10 deg/h"

A parameter claim overrides an item claim for that parameter. A claim with ``k = 2`` is read as a
95 % claim (GUM 6.3.3, as Appendix A reads it); another ``k`` as ``p = 2Φ(k) − 1``.
"""

from __future__ import annotations

import dataclasses
import json
import math
import tomllib
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from decimal import Decimal
from pathlib import Path

import numpy as np
from scipy import special  # the quantiles themselves: scipy.stats takes 1.4 s to import

from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS, parameter
from plansim.config import Scenario
from plansim.io.scenario_file import load_scenario
from plansim.units import parse_quantity
from plansim.uncertainty.appendix_a import (APPENDIX_A, AppendixABudget, appendix_a_budget,
                                            reading_unit_description, reading_unit_in_si)
from plansim.uncertainty.gum import GumEvaluation, ParameterBudget, evaluate_gum
from plansim.uncertainty.mcm import (DEFAULT_DIGITS, DEFAULT_TRIALS_PER_BLOCK, JointRegionCheck, MonteCarloResult,
                                     adaptive_monte_carlo, correlation_matrix, coverage_against_truth,
                                     joint_region_check, numerical_tolerance, validate_gum)

__all__ = [
    "DEFAULT_MAX_TRIALS",
    "DEFAULT_TOLERANCE_FRACTION",
    "KG_PARAMETERS",
    "AppendixItemCheck",
    "Claim",
    "ParameterValidation",
    "ValidationReport",
    "add_validate_command",
    "appendix_a_claims",
    "claim_verdict",
    "format_report",
    "load_claims",
    "parse_claims",
    "validate",
]

#: JCGM 101 8.2: a Monte Carlo run used to validate the GUM is taken to a tolerance of δ/5.
DEFAULT_TOLERANCE_FRACTION = 0.2
#: Upper limit of the adaptive procedure's trials (memory: 39 doubles per trial).
DEFAULT_MAX_TRIALS = 1_000_000
#: The nine elements of Kg, checked jointly (JCGM 102).
KG_PARAMETERS = tuple(p.name for p in PARAMETERS if p.group == "Kg")
#: Binomial standard deviations allowed between an observed coverage and its nominal value.
COVERAGE_Z = 3.0
#: A claim covering more than its nominal probability is called over-stated when it is more than
#: this factor wider than the interval the Monte Carlo needs (as plansim.uncertainty.appendix_a).
OVERSTATEMENT_FACTOR = 2.0


# ----------------------------------------------------------------------------- claims


@dataclass(frozen=True)
class Claim:
    """A stated expanded uncertainty of one parameter, in SI.

    Attributes
    ----------
    parameter : str
        Parameter symbol.
    expanded_uncertainty : float
        ``U`` in the parameter's SI unit.
    coverage_factor : float
        ``k`` of the claim.
    coverage_probability : float
        The probability the claim stands for: 0.95 for ``k = 2`` (GUM 6.3.3), else ``2Φ(k) − 1``.
    source : str
        Where the claim comes from (``"Appendix A A.2 (printed)"``, a file and its table).
    """

    parameter: str
    expanded_uncertainty: float
    coverage_factor: float
    coverage_probability: float
    source: str


def _claim_probability(k: float) -> float:
    return 0.95 if k == 2.0 else float(2.0 * special.ndtr(k) - 1.0)


def appendix_a_claims(scenario: Scenario, budgets=APPENDIX_A) -> dict[str, Claim]:
    """The printed Appendix A expanded uncertainties as claims on the 27 parameters they cover (SI)."""
    out = {}
    for budget in budgets:
        for name in budget.parameters:
            unit = float(reading_unit_in_si(budget, name, scenario))
            out[name] = Claim(name, budget.printed_expanded_uncertainty * unit, budget.coverage_factor,
                              _claim_probability(budget.coverage_factor), f"Appendix A {budget.item} (printed)")
    return out


def _claim_number(raw, where: str) -> float:
    if isinstance(raw, bool) or not isinstance(raw, (int, float, str)):
        raise TypeError(f"{where} = {raw!r}: expected a number")
    try:
        value = float(raw)
    except ValueError:
        raise ValueError(f"{where} = {raw!r}: an Appendix A item's U is a plain number in the item's reading "
                         "unit (e.g. 5.36e-4), not a quantity with a unit") from None
    if not (math.isfinite(value) and value > 0):
        raise ValueError(f"{where} = {raw!r}: must be finite and > 0")
    return value


def _check_claim_entry(entry, where: str) -> None:
    """A claim is a table with U (required) and k (optional)."""
    if not isinstance(entry, Mapping):
        raise TypeError(f"{where} must be a table with U (and k)")
    if set(entry) - {"U", "k"} or "U" not in entry:
        raise ValueError(f"{where}: keys {sorted(entry)}; expected U (required) and k (optional)")


def _claim_k(entry: Mapping, where: str) -> float:
    k = entry.get("k", 2)
    if isinstance(k, bool) or not isinstance(k, (int, float)) or not (math.isfinite(k) and k > 0):
        raise ValueError(f"{where}.k = {k!r}: the coverage factor must be a number > 0")
    return float(k)


def parse_claims(document: Mapping, scenario: Scenario, source: str = "claims") -> dict[str, Claim]:
    """Claims from a parsed claims document (module docstring), in SI.

    Raises
    ------
    ValueError, TypeError
        Unknown section, item, parameter or key; a missing or non-positive ``U``; a wrong unit.
    """
    if not isinstance(document, Mapping):
        raise TypeError(f"{source}: expected a TOML table, got {type(document).__name__}")
    unknown = set(document) - {"items", "parameters"}
    if unknown:
        raise ValueError(f"{source}: unknown section(s) {', '.join(sorted(map(repr, unknown)))}; "
                         "allowed: 'items', 'parameters'")
    claims: dict[str, Claim] = {}
    items = document.get("items", {})
    if not isinstance(items, Mapping):
        raise TypeError(f"{source}: [items] must be a table of Appendix A items")
    for item, entry in items.items():
        where = f"{source}: items.{item!r}"
        budget = appendix_a_budget(item) if item in {b.item for b in APPENDIX_A} else None
        if budget is None:
            raise ValueError(f"{where}: unknown Appendix A item; allowed: {', '.join(b.item for b in APPENDIX_A)}")
        _check_claim_entry(entry, where)
        U = _claim_number(entry["U"], f"{where}.U")
        k = _claim_k(entry, where)
        for name in budget.parameters:
            unit = float(reading_unit_in_si(budget, name, scenario))
            claims[name] = Claim(name, U * unit, k, _claim_probability(k),
                                 f"{source} [items.{item}] U = {U:g} {reading_unit_description(budget, scenario)}")
    parameters = document.get("parameters", {})
    if not isinstance(parameters, Mapping):
        raise TypeError(f"{source}: [parameters] must be a table of parameters")
    for name, entry in parameters.items():
        where = f"{source}: parameters.{name}"
        if name not in PARAMETER_INDEX:
            raise ValueError(f"{where}: unknown parameter; known: {', '.join(PARAMETER_NAMES)}")
        _check_claim_entry(entry, where)
        U = parse_quantity(entry["U"], parameter(name).kind, f"{where}.U")
        if not (math.isfinite(U) and U > 0):
            raise ValueError(f"{where}.U = {entry['U']!r}: must be > 0")
        k = _claim_k(entry, where)
        claims[name] = Claim(name, U, k, _claim_probability(k), f"{source} [parameters.{name}] U = {entry['U']}")
    if not claims:
        raise ValueError(f"{source}: no claims; give [items.\"A.x\"] or [parameters.<name>] tables with U")
    return claims


def load_claims(path, scenario: Scenario) -> dict[str, Claim]:
    """Claims from a TOML file (module docstring)."""
    p = Path(path)
    if not p.is_file():
        raise ValueError(f"--claims {str(path)!r}: no such file")
    try:
        with open(p, "rb") as fh:
            document = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"claims file {str(path)!r} is not valid TOML: {exc}") from None
    return parse_claims(document, scenario, source=p.name)


def claim_verdict(coverage: float, n: int, probability: float, factor: float) -> str:
    """Verdict on a claimed ``U`` from its coverage of the truth over *n* trials.

    ``"under-stated ×F"`` if ``coverage < p − tol``; ``"over-stated ×F"`` if ``coverage ≥ p + tol``
    and ``F > 2``; else ``"supported"``. ``tol`` = 3 binomial standard deviations
    (``3·sqrt(p(1 − p)/n)``), ``F = U_claimed / U_needed`` with ``U_needed`` the p-quantile of
    ``|E|`` (as :func:`plansim.uncertainty.appendix_a.appendix_a_verdict`).
    """
    tol = COVERAGE_Z * math.sqrt(probability * (1.0 - probability) / n)
    if coverage < probability - tol:
        return f"under-stated ×{factor:.3g}"
    if coverage >= probability + tol and factor > OVERSTATEMENT_FACTOR:
        return f"over-stated ×{factor:.3g}"
    return "supported"


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

    All uncertainties in the item's reading unit (``reading_unit``).
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

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        for key in ("parameters", "slips", "gum_U95", "mcm_U95"):
            d[key] = list(d[key])
        return d


@dataclass(frozen=True)
class ValidationReport:
    """Everything :func:`validate` found (module docstring)."""

    scenario: str
    description: str
    gum: GumEvaluation
    mcm: MonteCarloResult
    parameters: tuple[ParameterValidation, ...]
    appendix_items: tuple[AppendixItemCheck, ...]
    joint: JointRegionCheck
    mcm_correlation: np.ndarray
    digits: int
    tolerance_fraction: float
    claims_source: str

    def parameter(self, name: str) -> ParameterValidation:
        if name not in PARAMETER_INDEX:
            raise ValueError(f"unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")
        return self.parameters[PARAMETER_INDEX[name]]

    def item(self, item: str) -> AppendixItemCheck:
        for check in self.appendix_items:
            if check.item == item:
                return check
        raise ValueError(f"no Appendix A item {item!r} in this report; it has "
                         f"{', '.join(c.item for c in self.appendix_items) or 'none'}")

    def as_dict(self) -> dict:
        """Plain JSON-ready dictionary (strict JSON: ``inf`` as the string ``"inf"``, ``nan`` as ``null``)."""
        gum_corr = self.gum.correlation()
        return _json_ready({
            "scenario": self.scenario,
            "description": self.description,
            "claims": self.claims_source,
            "mcm": {"trials": self.mcm.trials, "blocks": self.mcm.blocks, "trials_per_block": self.mcm.trials_per_block,
                    "seed": self.mcm.seed, "digits": self.digits, "tolerance_fraction": self.tolerance_fraction,
                    "converged": self.mcm.converged, "path": self.mcm.path},
            "parameters": [p.as_dict() for p in self.parameters],
            "appendix_a": [c.as_dict() for c in self.appendix_items],
            "joint_Kg": self.joint.as_dict(),
            "correlation": {"names": list(PARAMETER_NAMES), "mcm": np.round(self.mcm_correlation, 6).tolist(),
                            "gum": np.round(gum_corr, 6).tolist()},
            "gum_budgets": [b.as_dict() for b in self.gum.budgets],
        })


def _json_ready(value):
    """Recursively: numpy scalars to Python, ``nan`` to None, ``±inf`` to ``"inf"``/``"-inf"`` (strict JSON)."""
    if isinstance(value, dict):
        return {k: _json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_json_ready(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        if math.isnan(value):
            return None
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
    return value


# ----------------------------------------------------------------------------- the orchestration


def _reasons(budget: ParameterBudget, mc: MonteCarloResult, i: int, delta: float, validated: bool) -> tuple[str, ...]:
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


def _significant_digits(value: float) -> int:
    return len(Decimal(repr(value)).normalize().as_tuple().digits)


def _round_to(value: float, digits: int, up: bool) -> float:
    exponent = math.floor(math.log10(abs(value))) - digits + 1
    scaled = value / 10.0**exponent
    return (math.ceil(scaled - 1e-9) if up else round(scaled)) * 10.0**exponent


def _appendix_slips(budget: AppendixABudget) -> tuple[str, ...]:
    """The printed-arithmetic slips of one budget (digest §1.4), in words with their numbers."""
    slips = []
    for c in budget.components:
        if c.combination_as_printed == "linear_sum":
            slips.append(
                f"linear-sum slip ({c.clause}): {c.symbol} = {c.count} × {c.value_per_reading:g} = "
                f"{c.printed_value:g} "
                f"adds the readings linearly; the model's sensitivity is {c.sensitivity_coefficient:.3g} per reading "
                f"and the GUM law of propagation (JCGM 100 5.1.2) gives c·√n·u = {c.gum_standard_uncertainty:.3g}")
    arithmetic = budget.recomputed_expanded_uncertainty()
    printed = budget.printed_expanded_uncertainty
    digits = _significant_digits(printed)
    if not math.isclose(_round_to(arithmetic, digits, up=False), printed, rel_tol=1e-9):
        if math.isclose(_round_to(arithmetic, digits, up=True), printed, rel_tol=1e-9):
            nearest = _round_to(arithmetic, digits, up=False)
            slips.append(f"rounding: k·u_c = {arithmetic:.5g} is printed as {printed:g}, rounded up to {digits} "
                         f"digits (GUM 7.2.6 allows rounding up; to nearest it is {nearest:g})")
        else:
            uc = budget.recomputed_combined_standard_uncertainty()
            slips.append(f"rounding slip: k·u_c = {budget.coverage_factor:g} × {uc:.4g} = {arithmetic:.4g}, "
                         f"printed {printed:g}")
    slips.append("u1 (relative rate error), u2 (fraction of full scale) and u3 (output units) are added without "
                 "units or sensitivity coefficients (digest §1.4)")
    return tuple(slips)


def validate(scenario: Scenario | str = "jjf2003", claims: Mapping[str, Claim] | None = None, *,
             digits: int = DEFAULT_DIGITS, trials_per_block: int = DEFAULT_TRIALS_PER_BLOCK,
             max_trials: int = DEFAULT_MAX_TRIALS, seed: int | None = None,
             tolerance_fraction: float = DEFAULT_TOLERANCE_FRACTION, path: str = "auto",
             coverage_probability: float = 0.95, joint_parameters=KG_PARAMETERS, monitor=None,
             progress: Callable[[int, int, float], None] | None = None) -> ValidationReport:
    """GUM budget, adaptive MCM, JCGM 101 §8 validation and coverage of the truth for a scenario.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario or a built-in name / TOML path.
    claims : mapping of parameter name -> Claim, optional
        Stated expanded uncertainties (:func:`load_claims`); default the Appendix A budgets
        (:func:`appendix_a_claims`).
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
    path : {"auto", "sample", "segment"}
        Simulation path.
    coverage_probability : float
        ``p`` (0.95).
    joint_parameters : sequence of str
        Outputs checked jointly (JCGM 102; default the nine Kg).
    monitor : sequence of str, optional
        The outputs whose numerical tolerance stops the Monte Carlo (default all 39; every output
        is validated, but those not monitored only to the accuracy the run happens to reach).
    progress : callable, optional
        Passed to :func:`plansim.uncertainty.mcm.adaptive_monte_carlo`.

    Returns
    -------
    ValidationReport
    """
    sc = scenario if isinstance(scenario, Scenario) else load_scenario(scenario) if isinstance(scenario, str) else None
    if sc is None:
        raise TypeError(f"scenario = {scenario!r}: expected a Scenario, a built-in scenario name or a TOML path")
    if isinstance(tolerance_fraction, bool) or not isinstance(tolerance_fraction, (int, float)) \
            or not 0.0 < tolerance_fraction <= 1.0:
        raise ValueError(f"tolerance_fraction = {tolerance_fraction!r}: must lie in (0, 1] (JCGM 101 8.2 uses 1/5)")
    if claims is None:
        claims = appendix_a_claims(sc)
        claims_source = "Appendix A of JJF 2003-2022 as printed (k = 2)"
    else:
        if not isinstance(claims, Mapping) or not all(isinstance(c, Claim) for c in claims.values()):
            raise TypeError("claims: expected a mapping of parameter name -> Claim (see load_claims)")
        sources = sorted({c.source.split(" [")[0] for c in claims.values()})
        claims_source = ", ".join(sources)

    gum = evaluate_gum(sc, coverage_probability)
    u_gum = gum.standard_uncertainty
    delta_gum = np.asarray(numerical_tolerance(u_gum, digits))
    mc = adaptive_monte_carlo(sc, digits=digits, trials_per_block=trials_per_block, max_trials=max_trials, seed=seed,
                              tolerance=tolerance_fraction * delta_gum, parameters=monitor,
                              coverage_probability=coverage_probability, path=path, progress=progress)
    outcome = validate_gum(gum.estimate, gum.expanded_uncertainty, u_gum, mc.low, mc.high, digits)
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
            factor = claim.expanded_uncertainty / needed_claim if needed_claim > 0 else math.inf
            covered = float(coverage_claimed[i])
            verdict = claim_verdict(covered, n, probability, factor)
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

    items = []
    for budget in APPENDIX_A:
        names = budget.parameters
        units = np.array([float(reading_unit_in_si(budget, nm, sc)) for nm in names])
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
        factor = claimed_U / needed if needed > 0 else math.inf
        same = math.sqrt(sum(c.gum_standard_uncertainty**2 for c in budget.components))
        items.append(AppendixItemCheck(
            item=budget.item, quantity=budget.quantity, reading_unit=reading_unit_description(budget, sc),
            parameters=tuple(names), printed_uc=budget.printed_combined_standard_uncertainty,
            printed_U=budget.printed_expanded_uncertainty, arithmetic_U=budget.recomputed_expanded_uncertainty(),
            same_inputs_gum_uc=same, same_inputs_gum_U=budget.coverage_factor * same, slips=_appendix_slips(budget),
            claimed_U=claimed_U,
            gum_U95=tuple(float(gum.budgets[k].expanded_uncertainty / u) for k, u in zip(idx, units)),
            mcm_U95=tuple(float(np.quantile(abs_errors[:, k], coverage_probability) / u) for k, u in zip(idx, units)),
            coverage=covered, verdict=claim_verdict(covered, pooled.size, probability, factor)))

    joint = joint_region_check(errors, joint_parameters, coverage_probability, gum_covariance=gum.covariance)
    return ValidationReport(scenario=sc.name, description=sc.description, gum=gum, mcm=mc, parameters=tuple(results),
                            appendix_items=tuple(items), joint=joint, mcm_correlation=correlation_matrix(errors),
                            digits=int(digits), tolerance_fraction=float(tolerance_fraction),
                            claims_source=claims_source)


# ----------------------------------------------------------------------------- text report


def _fmt(x, digits: int = 4) -> str:
    if x is None:
        return "—"
    if isinstance(x, float) and math.isnan(x):
        return "—"
    if isinstance(x, float) and math.isinf(x):
        return "∞"
    return f"{x:.{digits}g}"


def _budget_table(budget: ParameterBudget) -> list[str]:
    lines = [f"  {'input':30s} {'type':4s} {'u(x_i)':>10s} {'unit':>7s} {'c_i':>10s} {'u_i(y)':>10s} {'share':>6s} "
             f"{'ν_i':>8s}  distribution"]
    uc = budget.combined_standard_uncertainty
    for line in budget.inputs:
        share = (line.contribution / uc) ** 2 if uc > 0 else math.nan
        unit = line.input_unit if len(line.input_unit) <= 7 else "SI"
        lines.append(f"  {line.name[:30]:30s} {line.evaluation:4s} {_fmt(line.standard_uncertainty, 3):>10s} "
                     f"{unit:>7s} {_fmt(line.sensitivity, 3):>10s} {_fmt(line.contribution, 3):>10s} "
                     f"{share:>6.1%} {_fmt(line.dof, 3):>8s}  {line.distribution}")
    lines.append(f"  u_c = {_fmt(uc)} {budget.unit}, ν_eff = {_fmt(budget.effective_dof, 3)}, "
                 f"k({budget.coverage_probability:.0%}) = {budget.coverage_factor:.3f}, "
                 f"U95 = {_fmt(budget.expanded_uncertainty)} {budget.unit}"
                 f"   [largest 2nd-order term {_fmt(budget.largest_second_order, 2)}]")
    if budget.systematic_effects:
        parts = [f"{e.name} {e.bias:+.3g}" + (f" ({e.bias / uc:+.2g} u_c)" if uc > 0 else "")
                 for e in budget.systematic_effects]
        lines.append(f"  not corrected (bias; GUM 3.2.4 asks to correct): y = {budget.estimate:+.4g} = "
                     + "; ".join(parts))
    return lines


def format_report(report: ValidationReport, details: bool = True) -> str:
    """The text report of ``plansim validate``: summary, Appendix A, JCGM 102, per-parameter budgets."""
    mc = report.mcm
    out = [
        f"plansim validate — scenario {report.scenario!r}: {report.description}",
        f"GUM (JCGM 100) budgets derived from the schedule; adaptive Monte Carlo (JCGM 101 7.9.4): "
        f"{mc.blocks} blocks × {mc.trials_per_block} = {mc.trials} trials ({mc.path} path, seed {mc.seed}), "
        f"n_dig = {report.digits}, run to {report.tolerance_fraction:g}·δ of the GUM u_c (JCGM 101 8.2): "
        + ("reached" if mc.converged else "NOT reached (max trials)"),
        f"Output quantity: the error E = estimate − truth of each parameter (SI). Claims: {report.claims_source}.",
        "",
        "Summary (JCGM 101 8: validated if d_low and d_high ≤ δ; coverage = fraction of trials with |E| ≤ U)",
        f"{'name':5s} {'GUM y':>10s} {'GUM u_c':>10s} {'ν_eff':>7s} {'U95':>10s} {'MCM u':>10s} {'MCM low':>11s} "
        f"{'MCM high':>11s} {'δ':>8s} {'d_low':>8s} {'d_high':>8s} {'valid':>5s} {'cov GUM':>7s} "
        f"{'claimed U':>10s} {'cov claim':>9s}  claim verdict",
    ]
    for p in report.parameters:
        out.append(
            f"{p.name:5s} {p.gum_y:>10.3g} {p.gum_u:>10.3g} {_fmt(p.gum_dof, 2):>7s} {p.gum_U95:>10.3g} "
            f"{p.mcm_u:>10.3g} "
            f"{p.mcm_low:>11.3g} {p.mcm_high:>11.3g} {p.delta:>8.2g} {p.d_low:>8.2g} {p.d_high:>8.2g} "
            f"{'yes' if p.validated else 'NO':>5s} {p.coverage_gum:>7.1%} {_fmt(p.claimed_U, 3):>10s} "
            f"{'—' if p.coverage_claimed is None else format(p.coverage_claimed, '.1%'):>9s}  "
            f"{p.claim_verdict or '—'}")
    failed = [p for p in report.parameters if not p.validated]
    out.append(f"GUM framework validated for {N_PARAMETERS - len(failed)} of {N_PARAMETERS} parameters"
               + (f"; not for {', '.join(p.name for p in failed)}" if failed else ""))

    if report.appendix_items:
        out += ["", "Appendix A of JJF 2003-2022 — claimed and achieved (reading units; k = 2)"]
        for c in report.appendix_items:
            out.append(f"{c.item} {c.quantity} — reading: {c.reading_unit}")
            out.append(f"    printed u_c {c.printed_uc:g}, U {c.printed_U:g}; recomputed k·u_c {c.arithmetic_U:.4g}; "
                       f"the same inputs by the GUM: u_c {c.same_inputs_gum_uc:.3g}, U {c.same_inputs_gum_U:.3g}")
            for slip in c.slips:
                out.append(f"    ! {slip}")
            gum_list = ", ".join(f"{n} {v:.3g}" for n, v in zip(c.parameters, c.gum_U95))
            mcm_list = ", ".join(f"{n} {v:.3g}" for n, v in zip(c.parameters, c.mcm_U95))
            out.append(f"    achieved by this schedule: GUM U95 {gum_list}")
            out.append(f"                               MCM U95 {mcm_list}")
            out.append(f"    claimed U {c.claimed_U:g} covers the truth in {c.coverage:.2%} of the trials: {c.verdict}")

    j = report.joint
    out += ["", f"Several outputs at once (JCGM 102): {', '.join(j.parameters)}",
            f"    inside the {j.coverage_probability:.0%} ellipsoid χ²_{j.dimension}({j.coverage_probability:g}) = "
            f"{j.chi2_quantile:.3g}: {j.fraction_in_ellipsoid:.2%} of the trials (MCM k_p = {j.mc_k:.3g}, "
            f"√χ² = {math.sqrt(j.chi2_quantile):.3g}); GUM ellipsoid about the truth: "
            f"{j.gum_fraction_in_ellipsoid:.2%}",
            f"    all {len(j.parameters)} inside their marginal k = {j.marginal_k:g} intervals: "
            f"{j.fraction_all_marginal:.2%}; box for a joint {j.coverage_probability:.0%}: k = {j.box_k:.3g}",
            f"    {'! ' if j.misleading else ''}{j.message}"]
    corr = report.mcm_correlation
    idx = [PARAMETER_INDEX[n] for n in j.parameters]
    pairs = sorted(((abs(corr[a, b]), a, b) for ai, a in enumerate(idx) for b in idx[ai + 1:]), reverse=True)[:3]
    if pairs:
        out.append("    strongest correlations: " + ", ".join(
            f"r({PARAMETER_NAMES[a]}, {PARAMETER_NAMES[b]}) = {corr[a, b]:+.3f}" for _, a, b in pairs))

    gum_corr = report.gum.correlation()
    pairs = sorted(((abs(corr[a, b]), a, b) for a in range(N_PARAMETERS) for b in range(a + 1, N_PARAMETERS)),
                   reverse=True)[:8]
    out.append("Correlation of the estimated parameters (JCGM 102; Kg, G, Ka, P come from shared fits), "
               "strongest pairs, MCM (GUM):")
    out.append("    " + ", ".join(f"r({PARAMETER_NAMES[a]}, {PARAMETER_NAMES[b]}) = {corr[a, b]:+.3f} "
                                  f"({gum_corr[a, b]:+.3f})" for _, a, b in pairs))

    if details:
        for p, budget in zip(report.parameters, report.gum.budgets):
            spec = parameter(p.name)
            out += ["", f"== {p.name}: {spec.long_name} [{p.unit}]"
                    + (f" — Appendix A {p.appendix_item}" if p.appendix_item else "")]
            out.append("GUM budget (JCGM 100 5.1.2; output: the error E of the parameter)")
            out += _budget_table(budget)
            out.append(f"MCM: y = {p.mcm_y:.4g}, u = {p.mcm_u:.4g}, {mc.coverage_probability:.0%} interval "
                       f"[{p.mcm_low:.4g}, {p.mcm_high:.4g}] "
                       f"(shortest [{p.mcm_shortest_low:.4g}, {p.mcm_shortest_high:.4g}])")
            out.append(f"Validation (JCGM 101 8): δ = {p.delta:.2g}, d_low = {p.d_low:.2g}, "
                       f"d_high = {p.d_high:.2g} → "
                       f"GUM framework validated: {'yes' if p.validated else 'no'}")
            for reason in p.reasons:
                out.append(f"    because {reason}")
            line = f"Coverage of the truth: GUM U95 {p.coverage_gum:.2%}"
            if p.claimed_U is not None:
                line += (f"; claimed U = {p.claimed_U:.4g} ({p.claim_source}) {p.coverage_claimed:.2%} → "
                         f"{p.claim_verdict} (U needed for {p.claim_probability:.0%}: "
                         f"{p.claimed_U / p.claim_factor:.3g})")
            out.append(line)
            if budget.appendix_a is not None:
                a = budget.appendix_a
                out.append(f"Appendix A {a.item} in its reading unit (1 unit = {a.reading_unit_si:.4g} {p.unit}): "
                           f"printed u1 {a.printed_u[0]:g}, u2 {a.printed_u[1]:g}, u3 {a.printed_u[2]:g} → "
                           f"u_c {a.printed_uc:g}, "
                           f"U {a.printed_U:g} (same inputs by the GUM: U {a.same_inputs_gum_U:.3g}); this schedule: "
                           f"table {a.plansim_u[0]:.3g}, acquisition {a.plansim_u[1]:.3g}, repeatability "
                           f"{a.plansim_u[2]:.3g} → u_c {a.plansim_uc:.3g}, U95 {a.plansim_U95:.3g}")
    return "\n".join(out)


# ----------------------------------------------------------------------------- command line


def _stderr_progress(label: str):
    import sys
    import time

    start = time.perf_counter()

    def report(done: int, blocks: int, worst: float) -> None:
        elapsed = time.perf_counter() - start
        sys.stderr.write(f"\r{label}: {blocks} blocks, {done} trials, max 2s/δ = {worst:.3g} ({elapsed:.0f} s)   ")
        sys.stderr.flush()

    return report


def _cmd_validate(args) -> int:
    import sys

    scenario = load_scenario(args.scenario)
    claims = load_claims(args.claims, scenario) if args.claims else None
    for option, value, minimum in (("--trials-per-block", args.trials_per_block, 2),
                                   ("--max-trials", args.max_trials, 1), ("--digits", args.digits, 1)):
        if value < minimum:
            raise ValueError(f"{option} {value}: must be >= {minimum}")
    if args.seed is not None and args.seed < 0:
        raise ValueError(f"--seed {args.seed}: must be >= 0")
    progress = None if (args.quiet or args.json) else _stderr_progress(f"plansim validate {scenario.name}")
    report = validate(scenario, claims, digits=args.digits, trials_per_block=args.trials_per_block,
                      max_trials=args.max_trials, seed=args.seed, path=args.path, progress=progress)
    if progress is not None:
        sys.stderr.write("\n")
    if args.json:
        print(json.dumps(report.as_dict(), indent=2))
    else:
        print(format_report(report, details=not args.summary))
    return 0


def add_validate_command(subparsers) -> None:
    """Register ``plansim validate [SCENARIO] [--claims claims.toml] [--json] …`` on *subparsers*."""
    p = subparsers.add_parser(
        "validate", help="GUM budget from the schedule, validated by adaptive Monte Carlo (JCGM 101/102); "
                         "checks a claimed budget (default: JJF 2003 Appendix A)")
    p.add_argument("scenario", nargs="?", default="jjf2003",
                   help="built-in scenario name (see 'plansim scenarios') or a TOML path; default jjf2003")
    p.add_argument("--claims", default=None,
                   help="TOML file of claimed expanded uncertainties ([items.\"A.2\"] U = ...; [parameters.Bgx] "
                        "U = \"10 deg/h\"; k = 2 by default); default: the Appendix A budgets as printed")
    p.add_argument("--json", action="store_true", help="print one JSON object instead of the text report")
    p.add_argument("--trials-per-block", type=int, default=DEFAULT_TRIALS_PER_BLOCK,
                   help=f"M, Monte Carlo trials per block (JCGM 101 7.9.4 b); default {DEFAULT_TRIALS_PER_BLOCK}")
    p.add_argument("--max-trials", type=int, default=DEFAULT_MAX_TRIALS,
                   help=f"stop the adaptive procedure here at the latest (default {DEFAULT_MAX_TRIALS})")
    p.add_argument("--seed", type=int, default=None, help="root seed of the block seeds (default: the scenario's)")
    p.add_argument("--digits", type=int, default=DEFAULT_DIGITS,
                   help="n_dig, significant digits of the numerical tolerance δ "
                        f"(JCGM 101 7.9.2; default {DEFAULT_DIGITS})")
    p.add_argument("--path", choices=("auto", "sample", "segment"), default="auto",
                   help="simulation path: auto takes the segment-statistics path only where it is exact")
    p.add_argument("--summary", action="store_true", help="text report without the per-parameter budgets")
    p.add_argument("--quiet", action="store_true", help="no progress line on stderr")
    p.set_defaults(func=_cmd_validate)
