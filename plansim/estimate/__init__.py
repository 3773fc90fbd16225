"""Data reduction: the JJF 2003-2022 estimators, eq. (3)-(13)."""

from plansim.estimate.jjf2003 import (
                                      DESIGN_MATRIX_A,
                                      check_design,
                                      line_fit,
                                      multi_position_fit,
                                      rate_sensitivity,
                                      reduce,
                                      reduction_key,
                                      reduction_matrix,
                                      segment_mean,
)

__all__ = ["DESIGN_MATRIX_A", "check_design", "line_fit", "multi_position_fit", "rate_sensitivity", "reduce",
           "reduction_key", "reduction_matrix",
           "segment_mean"]
