"""JJF 1535-2015 Appendix A: the scale-factor and bias uncertainty budgets of a single-axis MEMS gyro, as printed.

A.1 (scale factor, relative; model (A.1) K = (F − F0 − v)/Ω, propagation (A.2)):

- u1 = 2.5e-4: the rate table, U_rel = 5e-4 with k = 2 (type B);
- u2 = 3.0e-5: the data acquisition, a 6½-digit voltmeter with U_rel = 6e-5, k = 2 (type B);
- u3 = 4.65e-4: measurement repeatability, "from a large amount of experimental data" on one gyro type (type A);
- u_c(K) = sqrt(u1² + u2² + u3²) = 5.29e-4, U_rel = 2·u_c = 1.1e-3 (A.1.3, A.1.4).

A.2 (bias; model (A.3) B0 = F/K, propagation (A.4), c(F) = 1/K, c(K) = −F/K², both read relative):

- u1 = 3.0e-5: the data acquisition as above (the text labels it "u2 = U_rel/2" in A.2.2 1), a slip: it is u1);
- u2 = u(K) = 5.29e-4 from A.1.3;
- u_c(B0) = sqrt(u1² + u2²) = 5.30e-4, U = 1.1e-3 (A.2.3, A.2.4).

The components reuse :class:`plansim.uncertainty.appendix_a.UncertaintyComponent` (one printed value each).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from plansim.uncertainty.appendix_a import UncertaintyComponent

#: Appendix A's coverage factor (k = 2, about 95 %)
COVERAGE_FACTOR = 2.0


@dataclass(frozen=True)
class Jjf1535Budget:
    """One JJF 1535 Appendix A budget as printed: its components and its printed u_c and U."""

    item: str
    quantity: str
    measurement_model: str
    components: tuple[UncertaintyComponent, ...]
    printed_combined_standard_uncertainty: float
    printed_expanded_uncertainty: float
    coverage_factor: float = COVERAGE_FACTOR

    @property
    def combined_standard_uncertainty(self) -> float:
        """u_c recomputed from the printed components (root sum of squares, GUM 5.1.2, c_i = 1 as printed)."""
        return math.sqrt(sum(c.printed_value**2 for c in self.components))

    @property
    def expanded_uncertainty(self) -> float:
        """U = k·u_c recomputed."""
        return self.coverage_factor * self.combined_standard_uncertainty


_ACQUISITION = dict(source="data acquisition (6½-digit voltmeter, U_rel = 6e-5, k = 2)", value_per_reading=3.0e-5,
                    count=1, combination_as_printed="single", printed_value=3.0e-5,
                    derivation="U_rel/k = 6e-5/2 (type B)")

SCALE_FACTOR = Jjf1535Budget(
    item="A.1", quantity="scale factor K (relative)",
    measurement_model="(A.1) K = (F − F0 − v)/Ω; (A.2) u_c²(K) = u²(F)/Ω² + u²(F0)/Ω² + (F − F0)²u²(Ω)/Ω⁴",
    components=(
        UncertaintyComponent(symbol="u1", source="rate table (U_rel = 5e-4, k = 2)", clause="A.1.2.2 1)",
                             value_per_reading=2.5e-4, count=1, combination_as_printed="single",
                             printed_value=2.5e-4, derivation="U_rel/k = 5e-4/2 (type B)"),
        UncertaintyComponent(symbol="u2", clause="A.1.2.2 2)", **_ACQUISITION),
        UncertaintyComponent(symbol="u3", source="measurement repeatability", clause="A.1.2.2 3)",
                             value_per_reading=4.65e-4, count=1, combination_as_printed="single",
                             printed_value=4.65e-4, derivation="from a large amount of data on one gyro type (type A)"),
    ),
    printed_combined_standard_uncertainty=5.29e-4, printed_expanded_uncertainty=1.1e-3)

BIAS = Jjf1535Budget(
    item="A.2", quantity="bias B0 (relative)",
    measurement_model="(A.3) B0 = F/K; (A.4) u_c²(B0) = u²(F)/K² + F²u²(K)/K⁴",
    components=(
        UncertaintyComponent(symbol="u1", clause="A.2.2 1) (printed as 'u2')", **_ACQUISITION),
        UncertaintyComponent(symbol="u2", source="the scale factor, u(K) from A.1.3", clause="A.2.2 2)",
                             value_per_reading=5.29e-4, count=1, combination_as_printed="single",
                             printed_value=5.29e-4, derivation="u(K) = 5.29e-4 (A.1.3)"),
    ),
    printed_combined_standard_uncertainty=5.30e-4, printed_expanded_uncertainty=1.1e-3)

#: the budgets by Appendix A item
BUDGETS = {b.item: b for b in (SCALE_FACTOR, BIAS)}
