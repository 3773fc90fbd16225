"""Measurement uncertainty: the published JJF 2003-2022 Appendix A budgets and their check by Monte Carlo.

See :mod:`plansim.uncertainty.appendix_a`.
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
