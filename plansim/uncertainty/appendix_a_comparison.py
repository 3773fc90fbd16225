"""JJF 2003-2022 Appendix A against Monte Carlo: each printed budget next to the errors the calibration makes.

For each budget of :data:`plansim.uncertainty.appendix_a.APPENDIX_A` the simulated errors
``estimate − truth`` of its parameters are converted into the budget's reading unit
(:func:`plansim.uncertainty.appendix_a.errors_in_reading_units`), pooled and summarised: bias,
standard deviation, the 95th percentile of ``|error|`` and the coverage of the printed ``U``
(read as a 95 % statement, JCGM 100 6.3.3), with the verdict of
:func:`plansim.uncertainty.metrology.coverage_verdict`.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX
from plansim.uncertainty.appendix_a import (
    APPENDIX_A,
    AppendixABudget,
    errors_in_reading_units,
    reading_unit_description,
    reading_unit_in_si,
)
from plansim.uncertainty.metrology.coverage import coverage_tolerance, coverage_verdict

__all__ = ["NOMINAL_COVERAGE", "ItemComparison", "ParameterComparison", "compare_with_appendix_a"]

#: Nominal coverage probability of an expanded uncertainty with k = 2 (GUM 6.2, 6.3.3: ≈ 95 %).
NOMINAL_COVERAGE = 0.95


def _statistics(errors: np.ndarray, expanded: float) -> tuple[float, float, float, float]:
    magnitude = np.abs(errors)
    return (float(np.mean(errors)), float(np.std(errors, ddof=1)),
            float(np.quantile(magnitude, NOMINAL_COVERAGE)), float(np.mean(magnitude <= expanded)))


@dataclass(frozen=True)
class ParameterComparison:
    """Monte Carlo errors of one parameter in the reading units of its Appendix A budget.

    Attributes
    ----------
    name : str
        Parameter symbol.
    mean : float
        Mean error (bias).
    std : float
        Standard deviation of the errors (ddof = 1).
    U95 : float
        95th percentile of ``|error|``.
    coverage : float
        Fraction of ``|error| ≤`` the printed ``U``.
    reading_unit_in_si : float
        SI size of one reading unit for this parameter (for A.1 the mean ``|truth|``).
    budget_U_si : float
        The printed ``U`` in SI (``U × reading_unit_in_si``).
    """

    name: str
    mean: float
    std: float
    U95: float
    coverage: float
    reading_unit_in_si: float
    budget_U_si: float

    def as_dict(self) -> dict:
        return {"name": self.name, "mean": self.mean, "std": self.std, "U95": self.U95,
                "coverage": self.coverage, "reading_unit_in_si": self.reading_unit_in_si,
                "budget_U_si": self.budget_U_si}


@dataclass(frozen=True)
class ItemComparison:
    """One Appendix A budget compared with the pooled Monte Carlo errors of its parameters.

    All error statistics are in the budget's reading units (module docstring).

    Attributes
    ----------
    item, quantity, reading : str
        From the budget.
    reading_unit : str
        The reading's unit, with its SI size in the scenario (:func:`reading_unit_description`).
    parameters : tuple of str
        The pooled parameters.
    n : int
        Number of pooled errors (trials × parameters).
    budget_uc, budget_U : float
        ``u_c`` and ``U`` as printed.
    coverage_factor : float
        ``k`` of the budget.
    arithmetic_uc, arithmetic_U : float
        ``u_c`` and ``U = k·u_c`` recomputed from the printed components.
    mc_bias : float
        Mean error.
    mc_u : float
        Standard deviation of the errors (ddof = 1), the Monte Carlo standard uncertainty.
    mc_U95 : float
        95th percentile of ``|error|``: half-width of the interval about the truth holding 95 % of errors.
    coverage : float
        Fraction of errors with ``|error| ≤ budget_U``.
    ratio : float
        ``mc_u / budget_uc``.
    tolerance : float
        ``3·sqrt(0.95·0.05/n)``, three binomial standard deviations of the coverage at 95 %
        (:func:`plansim.uncertainty.metrology.coverage_tolerance`).
    overstatement_factor : float
        ``budget_U / mc_U95`` (``inf`` when every error is zero).
    verdict : str
        :func:`plansim.uncertainty.metrology.coverage_verdict` at 95 %: ``"supported"``;
        ``"under-stated"`` if ``coverage < 0.95 − tolerance``; ``"over-stated ×F"`` if
        ``coverage ≥ 0.95 + tolerance`` and ``F = overstatement_factor > 2``.
    per_parameter : tuple of ParameterComparison
        The same statistics for each parameter alone.
    """

    item: str
    quantity: str
    reading: str
    reading_unit: str
    parameters: tuple[str, ...]
    n: int
    budget_uc: float
    budget_U: float
    coverage_factor: float
    arithmetic_uc: float
    arithmetic_U: float
    mc_bias: float
    mc_u: float
    mc_U95: float
    coverage: float
    ratio: float
    tolerance: float
    overstatement_factor: float
    verdict: str
    per_parameter: tuple[ParameterComparison, ...] = field(default_factory=tuple)

    def as_dict(self) -> dict:
        """Plain-Python dictionary for JSON (keys ``item``, ``budget_uc``, ``budget_U``, ``mc_u``,
        ``mc_U95``, ``coverage`` and the other attributes; ``per_parameter`` as a list of dicts)."""
        return {
            "item": self.item, "quantity": self.quantity, "reading": self.reading,
            "reading_unit": self.reading_unit, "parameters": list(self.parameters), "n": self.n,
            "budget_uc": self.budget_uc, "budget_U": self.budget_U, "coverage_factor": self.coverage_factor,
            "arithmetic_uc": self.arithmetic_uc, "arithmetic_U": self.arithmetic_U,
            "mc_bias": self.mc_bias, "mc_u": self.mc_u, "mc_U95": self.mc_U95, "coverage": self.coverage,
            "ratio": self.ratio, "tolerance": self.tolerance,
            "overstatement_factor": self.overstatement_factor, "verdict": self.verdict,
            "per_parameter": [p.as_dict() for p in self.per_parameter],
        }


def _check_parameter_array(name: str, value) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim != 2 or array.shape[1] != N_PARAMETERS:
        raise ValueError(f"{name}: shape {array.shape}; expected (trials, {N_PARAMETERS}) ordered as "
                         "plansim.model.parameters.PARAMETER_NAMES")
    if array.shape[0] < 2:
        raise ValueError(f"{name}: {array.shape[0]} trial(s); a standard deviation needs at least 2")
    return array


def compare_with_appendix_a(truth, estimate, scenario, budgets: Iterable[AppendixABudget] = APPENDIX_A
                            ) -> list[ItemComparison]:
    """Compare Monte Carlo calibration errors with the Appendix A budgets of JJF 2003-2022.

    For each budget the errors ``estimate − truth`` of its parameters are converted into the
    budget's reading units (:func:`errors_in_reading_units`), pooled, and summarised.

    Parameters
    ----------
    truth, estimate : (trials, 39) array_like
        True and estimated parameters, SI, ordered as :data:`plansim.model.parameters.PARAMETER_NAMES`.
    scenario : plansim.config.Scenario
        Supplies full scales, reference gravity and the ω² test rate for the readings.
    budgets : iterable of AppendixABudget
        Default: all of :data:`APPENDIX_A`.

    Returns
    -------
    list of ItemComparison
        One per budget, in the order given.
    """
    truth = _check_parameter_array("truth", truth)
    estimate = _check_parameter_array("estimate", estimate)
    if truth.shape != estimate.shape:
        raise ValueError(f"estimate: shape {estimate.shape} differs from truth's {truth.shape}")
    budgets = tuple(budgets)
    for budget in budgets:
        if not isinstance(budget, AppendixABudget):
            raise TypeError(f"budgets: element {budget!r} is not an AppendixABudget")
    results: list[ItemComparison] = []
    for budget in budgets:
        expanded = budget.printed_expanded_uncertainty
        pooled, per_parameter = [], []
        for name in budget.parameters:
            k = PARAMETER_INDEX[name]
            if not (np.all(np.isfinite(truth[:, k])) and np.all(np.isfinite(estimate[:, k]))):
                bad = int(np.argmax(~(np.isfinite(truth[:, k]) & np.isfinite(estimate[:, k]))))
                raise ValueError(f"parameter {name}: trial {bad} has truth {truth[bad, k]!r} and estimate "
                                 f"{estimate[bad, k]!r}; every value must be finite")
            errors = errors_in_reading_units(budget, name, estimate[:, k] - truth[:, k], scenario, truth[:, k])
            pooled.append(errors)
            mean, std, u95, coverage = _statistics(errors, expanded)
            unit = float(np.mean(reading_unit_in_si(budget, name, scenario, truth[:, k])))
            per_parameter.append(ParameterComparison(name=name, mean=mean, std=std, U95=u95, coverage=coverage,
                                                     reading_unit_in_si=unit, budget_U_si=expanded * unit))
        errors = np.concatenate(pooled)
        n = int(errors.size)
        mean, std, u95, coverage = _statistics(errors, expanded)
        verdict, factor = coverage_verdict(coverage, n, NOMINAL_COVERAGE, expanded, u95,
                                           show_understatement_factor=False)
        results.append(ItemComparison(
            item=budget.item, quantity=budget.quantity, reading=budget.reading,
            reading_unit=reading_unit_description(budget, scenario), parameters=tuple(budget.parameters), n=n,
            budget_uc=budget.printed_combined_standard_uncertainty, budget_U=expanded,
            coverage_factor=budget.coverage_factor,
            arithmetic_uc=budget.recomputed_combined_standard_uncertainty(),
            arithmetic_U=budget.recomputed_expanded_uncertainty(),
            mc_bias=mean, mc_u=std, mc_U95=u95, coverage=coverage,
            ratio=std / budget.printed_combined_standard_uncertainty,
            tolerance=coverage_tolerance(n, NOMINAL_COVERAGE), overstatement_factor=factor, verdict=verdict,
            per_parameter=tuple(per_parameter),
        ))
    return results
