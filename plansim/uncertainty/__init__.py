"""Measurement uncertainty: the published JJF 2003-2022 Appendix A budgets, GUM budgets derived from
the schedule, and their check by Monte Carlo.

- :mod:`plansim.uncertainty.appendix_a` — the five printed budgets as data, compared with the simulation;
- :mod:`plansim.uncertainty.gum` — law of propagation of uncertainty through the actual estimators (JCGM 100);
- :mod:`plansim.uncertainty.mcm` — adaptive Monte Carlo, coverage intervals, GUM validation (JCGM 101/102);
- :mod:`plansim.uncertainty.validate` — ``plansim validate``: a stated budget against all of the above.
"""

from plansim.uncertainty.appendix_a import (
    ACQUISITION_BITS,
    APPENDIX_A,
    COMBINATION_RULES,
    NOMINAL_COVERAGE,
    READING_KINDS,
    TABLE_COVERAGE_FACTOR,
    TABLE_EXPANDED_UNCERTAINTY,
    AppendixABudget,
    ItemComparison,
    ParameterComparison,
    UncertaintyComponent,
    acquisition_quantisation_uncertainty,
    appendix_a_budget,
    appendix_a_verdict,
    compare_with_appendix_a,
    coverage_tolerance,
    errors_in_reading_units,
    expanded_uncertainty_in_si,
    omega_squared_test_rate,
    reading_unit_description,
    reading_unit_in_si,
)

__all__ = [
    "ACQUISITION_BITS",
    "APPENDIX_A",
    "COMBINATION_RULES",
    "NOMINAL_COVERAGE",
    "READING_KINDS",
    "TABLE_COVERAGE_FACTOR",
    "TABLE_EXPANDED_UNCERTAINTY",
    "AppendixABudget",
    "ItemComparison",
    "ParameterComparison",
    "UncertaintyComponent",
    "acquisition_quantisation_uncertainty",
    "appendix_a_budget",
    "appendix_a_verdict",
    "compare_with_appendix_a",
    "coverage_tolerance",
    "errors_in_reading_units",
    "expanded_uncertainty_in_si",
    "omega_squared_test_rate",
    "reading_unit_description",
    "reading_unit_in_si",
]
