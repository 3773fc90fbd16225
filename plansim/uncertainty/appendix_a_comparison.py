"""JJF 2003-2022 Appendix A against Monte Carlo: each printed budget next to the errors the calibration makes.

For each budget of :data:`plansim.uncertainty.appendix_a.APPENDIX_A` the simulated errors
``estimate − truth`` of its parameters are converted into the budget's primary reading unit
(:func:`plansim.uncertainty.appendix_a.errors_in_reading_units`), pooled and summarised: bias,
standard deviation, the 95th percentile of ``|error|`` and the coverage of the printed ``U``
(read as a 95 % statement, JCGM 100 6.3.3), with the verdict of
:func:`plansim.uncertainty.metrology.coverage_verdict`.

The printed number means a different amount in each defensible reading of its unit
(``AppendixABudget.readings``), so the coverage, the 95 % point of ``|error|`` and the verdict are
also given per reading (:class:`ReadingComparison`), and each item says whether its verdict
*holds under every reading* (the same kind of verdict — over-stated, under-stated, supported or
too few trials — in all of them) or *depends on the reading* (:attr:`ItemComparison.reading_dependence`).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np

from plansim.model.parameters import N_PARAMETERS, PARAMETER_INDEX, parameter
from plansim.uncertainty.appendix_a import (
    APPENDIX_A,
    AppendixABudget,
    Reading,
    errors_in_reading_units,
    reading_unit_description,
    reading_unit_in_si,
)
from plansim.uncertainty.metrology.coverage import coverage_tolerance, coverage_verdict

__all__ = [
    "DEPENDS_ON_THE_READING",
    "HOLDS_UNDER_EVERY_READING",
    "NOMINAL_COVERAGE",
    "VERDICT_KINDS",
    "ItemComparison",
    "ParameterComparison",
    "ReadingComparison",
    "compare_with_appendix_a",
    "item_comparison",
    "reading_comparison",
    "reading_dependence",
    "verdict_kind",
]

#: Nominal coverage probability of an expanded uncertainty with k = 2 (GUM 6.2, 6.3.3: ≈ 95 %).
NOMINAL_COVERAGE = 0.95
#: The kinds of verdict of :func:`plansim.uncertainty.metrology.coverage_verdict`, without its numbers.
VERDICT_KINDS = ("over-stated", "under-stated", "supported", "too few trials")
#: :func:`reading_dependence` when every reading of an item gives the same kind of verdict …
HOLDS_UNDER_EVERY_READING = "holds under every reading"
#: … and when they do not.
DEPENDS_ON_THE_READING = "depends on the reading"


def verdict_kind(verdict: str) -> str:
    """The kind of a verdict (one of :data:`VERDICT_KINDS`): ``"over-stated ×21.7"`` -> ``"over-stated"``."""
    for kind in VERDICT_KINDS:
        if isinstance(verdict, str) and verdict.startswith(kind):
            return kind
    raise ValueError(f"verdict = {verdict!r}: not a verdict of coverage_verdict; it starts with one of "
                     f"{', '.join(map(repr, VERDICT_KINDS))}")


def reading_dependence(verdicts: Iterable[str]) -> str:
    """:data:`HOLDS_UNDER_EVERY_READING` if *verdicts* (one per reading) are all of one kind, else
    :data:`DEPENDS_ON_THE_READING`. An item with a single reading holds trivially."""
    kinds = {verdict_kind(v) for v in verdicts}
    if not kinds:
        raise ValueError("verdicts: empty; an item has at least one reading")
    return HOLDS_UNDER_EVERY_READING if len(kinds) == 1 else DEPENDS_ON_THE_READING


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
class ReadingComparison:
    """One Appendix A budget judged in one reading of its unit.

    The printed ``U`` is the same number in every reading; what changes is the amount it stands
    for. Statistics are of the pooled errors of the budget's parameters in this reading.

    Attributes
    ----------
    reading : str
        The reading's name (``Reading.name``: ``"FS_g"``, ``"deg/s"``, …).
    unit : str
        The reading's unit, with its SI size in the scenario (:func:`reading_unit_description`).
    si_unit : str
        SI unit of the budget's parameters, in which ``budget_U_si`` and ``mc_U95_si`` are given.
    unit_in_si : tuple of float
        SI size of one reading unit for each parameter (the mean over the trials for the relative reading).
    budget_U_si : tuple of float
        The printed ``U`` in SI for each parameter, ``U × unit_in_si``.
    coverage : float
        Fraction of the pooled errors with ``|error| ≤ U`` in this reading.
    mc_U95 : float
        95th percentile of the pooled ``|error|``, in this reading's units.
    mc_U95_si : float
        ``mc_U95 × mean(unit_in_si)``: the same in SI (exact when the unit is the same for every
        parameter and trial, i.e. every reading but the relative one, given one ω² test rate).
    overstatement_factor : float
        ``U / mc_U95``.
    verdict : str
        :func:`plansim.uncertainty.metrology.coverage_verdict` at 95 % in this reading.
    """

    reading: str
    unit: str
    si_unit: str
    unit_in_si: tuple[float, ...]
    budget_U_si: tuple[float, ...]
    coverage: float
    mc_U95: float
    mc_U95_si: float
    overstatement_factor: float
    verdict: str

    @property
    def verdict_kind(self) -> str:
        """The verdict without its numbers (:func:`verdict_kind`)."""
        return verdict_kind(self.verdict)

    @property
    def mean_budget_U_si(self) -> float:
        """The printed ``U`` in SI, averaged over the parameters (their common value for a constant reading)."""
        return float(np.mean(self.budget_U_si))

    def as_dict(self) -> dict:
        return {"reading": self.reading, "unit": self.unit, "si_unit": self.si_unit,
                "unit_in_si": list(self.unit_in_si), "budget_U_si": list(self.budget_U_si),
                "coverage": self.coverage, "mc_U95": self.mc_U95, "mc_U95_si": self.mc_U95_si,
                "overstatement_factor": self.overstatement_factor, "verdict": self.verdict,
                "verdict_kind": self.verdict_kind}


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
    readings : tuple of ReadingComparison
        The coverage, 95 % point and verdict in every reading of the budget's unit
        (``budget.readings``; the first, the primary one, repeats ``coverage``, ``mc_U95``,
        ``overstatement_factor`` and ``verdict``).
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
    readings: tuple[ReadingComparison, ...] = field(default_factory=tuple)

    @property
    def reading_dependence(self) -> str:
        """:data:`HOLDS_UNDER_EVERY_READING` or :data:`DEPENDS_ON_THE_READING` (:func:`reading_dependence`)."""
        return reading_dependence(r.verdict for r in self.readings) if self.readings else HOLDS_UNDER_EVERY_READING

    @property
    def holds_under_every_reading(self) -> bool:
        """Whether every reading gives the same kind of verdict."""
        return self.reading_dependence == HOLDS_UNDER_EVERY_READING

    def as_dict(self) -> dict:
        """Plain-Python dictionary for JSON (keys ``item``, ``budget_uc``, ``budget_U``, ``mc_u``,
        ``mc_U95``, ``coverage`` and the other attributes; ``per_parameter`` and ``readings`` as
        lists of dicts; ``reading_dependence`` and ``holds_under_every_reading``)."""
        return {
            "item": self.item, "quantity": self.quantity, "reading": self.reading,
            "reading_unit": self.reading_unit, "parameters": list(self.parameters), "n": self.n,
            "budget_uc": self.budget_uc, "budget_U": self.budget_U, "coverage_factor": self.coverage_factor,
            "arithmetic_uc": self.arithmetic_uc, "arithmetic_U": self.arithmetic_U,
            "mc_bias": self.mc_bias, "mc_u": self.mc_u, "mc_U95": self.mc_U95, "coverage": self.coverage,
            "ratio": self.ratio, "tolerance": self.tolerance,
            "overstatement_factor": self.overstatement_factor, "verdict": self.verdict,
            "per_parameter": [p.as_dict() for p in self.per_parameter],
            "readings": [r.as_dict() for r in self.readings],
            "reading_dependence": self.reading_dependence,
            "holds_under_every_reading": self.holds_under_every_reading,
        }


def _check_parameter_array(name: str, value) -> np.ndarray:
    array = np.asarray(value, dtype=float)
    if array.ndim != 2 or array.shape[1] != N_PARAMETERS:
        raise ValueError(f"{name}: shape {array.shape}; expected (trials, {N_PARAMETERS}) ordered as "
                         "plansim.model.parameters.PARAMETER_NAMES")
    if array.shape[0] < 2:
        raise ValueError(f"{name}: {array.shape[0]} trial(s); a standard deviation needs at least 2")
    return array


def reading_comparison(budget: AppendixABudget, reading: Reading, scenario, n: int, coverage: float,
                       u95: float, unit_in_si) -> ReadingComparison:
    """A :class:`ReadingComparison` from the pooled statistics of one reading.

    Parameters
    ----------
    budget : AppendixABudget
    reading : Reading
        One of ``budget.readings``.
    scenario : plansim.config.Scenario
        For the unit's description.
    n : int
        Pooled errors.
    coverage : float
        Fraction of them with ``|error| ≤ U`` in the reading.
    u95 : float
        Their 95 % point of ``|error|`` in the reading.
    unit_in_si : sequence of float
        SI size of one reading unit per parameter of the budget.
    """
    expanded = budget.printed_expanded_uncertainty
    units = tuple(float(u) for u in unit_in_si)
    verdict, factor = coverage_verdict(coverage, n, NOMINAL_COVERAGE, expanded, u95,
                                       show_understatement_factor=False)
    return ReadingComparison(
        reading=reading.name, unit=reading_unit_description(budget, scenario, reading),
        si_unit=parameter(budget.parameters[0]).si_unit, unit_in_si=units,
        budget_U_si=tuple(expanded * u for u in units), coverage=coverage, mc_U95=u95,
        mc_U95_si=u95 * float(np.mean(units)), overstatement_factor=factor, verdict=verdict)


def item_comparison(budget: AppendixABudget, scenario, n: int, mean: float, std: float, u95: float, coverage: float,
                    per_parameter: tuple[ParameterComparison, ...],
                    readings: tuple[ReadingComparison, ...]) -> ItemComparison:
    """An :class:`ItemComparison` from the pooled statistics of the primary reading (and *readings*).

    :func:`compare_with_appendix_a` (per-trial arrays) and
    :func:`plansim.report.summary.appendix_a_comparisons` (a streamed run) both assemble with it.
    """
    expanded = budget.printed_expanded_uncertainty
    verdict, factor = coverage_verdict(coverage, n, NOMINAL_COVERAGE, expanded, u95,
                                       show_understatement_factor=False)
    return ItemComparison(
        item=budget.item, quantity=budget.quantity, reading=budget.reading,
        reading_unit=reading_unit_description(budget, scenario), parameters=tuple(budget.parameters), n=n,
        budget_uc=budget.printed_combined_standard_uncertainty, budget_U=expanded,
        coverage_factor=budget.coverage_factor,
        arithmetic_uc=budget.recomputed_combined_standard_uncertainty(),
        arithmetic_U=budget.recomputed_expanded_uncertainty(),
        mc_bias=mean, mc_u=std, mc_U95=u95, coverage=coverage,
        ratio=std / budget.printed_combined_standard_uncertainty,
        tolerance=coverage_tolerance(n, NOMINAL_COVERAGE), overstatement_factor=factor, verdict=verdict,
        per_parameter=tuple(per_parameter), readings=tuple(readings),
    )


def compare_with_appendix_a(truth, estimate, scenario, budgets: Iterable[AppendixABudget] = APPENDIX_A
                            ) -> list[ItemComparison]:
    """Compare Monte Carlo calibration errors with the Appendix A budgets of JJF 2003-2022.

    For each budget the errors ``estimate − truth`` of its parameters are converted into the
    budget's primary reading units (:func:`errors_in_reading_units`), pooled, and summarised;
    the coverage, 95 % point and verdict are repeated in every other reading of the budget.

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
        for name in budget.parameters:
            k = PARAMETER_INDEX[name]
            if not (np.all(np.isfinite(truth[:, k])) and np.all(np.isfinite(estimate[:, k]))):
                bad = int(np.argmax(~(np.isfinite(truth[:, k]) & np.isfinite(estimate[:, k]))))
                raise ValueError(f"parameter {name}: trial {bad} has truth {truth[bad, k]!r} and estimate "
                                 f"{estimate[bad, k]!r}; every value must be finite")
        readings, primary = [], None
        for reading in budget.readings:
            pooled, per_parameter, units = [], [], []
            for name in budget.parameters:
                k = PARAMETER_INDEX[name]
                errors = errors_in_reading_units(budget, name, estimate[:, k] - truth[:, k], scenario, truth[:, k],
                                                 reading)
                pooled.append(errors)
                unit = float(np.mean(reading_unit_in_si(budget, name, scenario, truth[:, k], reading)))
                units.append(unit)
                if primary is None:
                    mean, std, u95, coverage = _statistics(errors, expanded)
                    per_parameter.append(ParameterComparison(name=name, mean=mean, std=std, U95=u95,
                                                             coverage=coverage, reading_unit_in_si=unit,
                                                             budget_U_si=expanded * unit))
            errors = np.concatenate(pooled)
            mean, std, u95, coverage = _statistics(errors, expanded)
            if primary is None:
                primary = (int(errors.size), mean, std, u95, coverage, tuple(per_parameter))
            readings.append(reading_comparison(budget, reading, scenario, int(errors.size), coverage, u95, units))
        n, mean, std, u95, coverage, per_parameter = primary
        results.append(item_comparison(budget, scenario, n, mean, std, u95, coverage, per_parameter, tuple(readings)))
    return results
