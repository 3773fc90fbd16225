"""Measurement uncertainty: a metrology core, and plansim's budgets on top of it.

The core, :mod:`plansim.uncertainty.metrology`, is JCGM 100/101/102 on plain arrays and callables
and imports nothing else from plansim. plansim's own budget builders:

- :mod:`~plansim.uncertainty.appendix_a` — the five JJF 2003-2022 Appendix A budgets as data, their
  printed arithmetic and the readings of their units;
- :mod:`~plansim.uncertainty.appendix_a_comparison` — each budget against Monte Carlo errors;
- :mod:`~plansim.uncertainty.gum` — the GUM budget of a schedule through the actual estimators
  (JCGM 100), built from :mod:`~plansim.uncertainty.sensitivities`,
  :mod:`~plansim.uncertainty.budget_lines`, :mod:`~plansim.uncertainty.drift`,
  :mod:`~plansim.uncertainty.quantisation` and :mod:`~plansim.uncertainty.systematic`, with the
  results of :mod:`~plansim.uncertainty.budget`;
- :mod:`~plansim.uncertainty.monte_carlo` — the adaptive Monte Carlo (JCGM 101) of a calibration,
  on a simulate callable the runner supplies;
- :mod:`~plansim.uncertainty.claims` — stated uncertainties (Appendix A or a parsed claims document);
- :mod:`~plansim.uncertainty.validation` — ``plansim validate``'s computation: all of the above together.
"""

from plansim.uncertainty.appendix_a import (
    ACQUISITION_BITS,
    APPENDIX_A,
    COMBINATION_RULES,
    READING_KINDS,
    TABLE_COVERAGE_FACTOR,
    TABLE_EXPANDED_UNCERTAINTY,
    AppendixABudget,
    UncertaintyComponent,
    acquisition_quantisation_uncertainty,
    appendix_a_budget,
    errors_in_reading_units,
    expanded_uncertainty_in_si,
    omega_squared_test_rate,
    printed_arithmetic_slips,
    reading_unit_description,
    reading_unit_in_si,
)
from plansim.uncertainty.appendix_a_comparison import (
    NOMINAL_COVERAGE,
    ItemComparison,
    ParameterComparison,
    compare_with_appendix_a,
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
    "compare_with_appendix_a",
    "errors_in_reading_units",
    "expanded_uncertainty_in_si",
    "omega_squared_test_rate",
    "printed_arithmetic_slips",
    "reading_unit_description",
    "reading_unit_in_si",
]
