"""The metrology core: JCGM 100, 101 and 102 on plain arrays and callables.

Nothing here knows plansim's scenarios, parameters or simulator: it imports only numpy, scipy
and the standard library (import-linter holds it to that). plansim's budget builders in
:mod:`plansim.uncertainty` sit on top of it.

- :mod:`~plansim.uncertainty.metrology.propagation` — JCGM 100: ``u_c`` (5.1.2), ``ν_eff`` by
  Welch–Satterthwaite (G.4.1), ``k_p`` from the t-distribution (G.3.4);
- :mod:`~plansim.uncertainty.metrology.monte_carlo` — JCGM 101 7.9: numerical tolerance (7.9.2),
  block seeds, the adaptive procedure (7.9.4) on a ``simulate(trials, seed)`` callable;
- :mod:`~plansim.uncertainty.metrology.intervals` — JCGM 101 7.7: probabilistically symmetric and
  shortest coverage intervals;
- :mod:`~plansim.uncertainty.metrology.validation` — JCGM 101 §8: validation of the GUM framework;
- :mod:`~plansim.uncertainty.metrology.several_outputs` — JCGM 102: correlation matrix, joint
  coverage region against marginal intervals;
- :mod:`~plansim.uncertainty.metrology.coverage` — coverage of the truth, the one coverage
  tolerance and the one verdict on a stated uncertainty.
"""

from plansim.uncertainty.metrology.coverage import (
    COVERAGE_Z,
    OVERSTATEMENT_FACTOR,
    coverage_against_truth,
    coverage_tolerance,
    coverage_verdict,
    minimum_trials_to_judge,
)
from plansim.uncertainty.metrology.intervals import coverage_intervals
from plansim.uncertainty.metrology.monte_carlo import (
    DEFAULT_DIGITS,
    DEFAULT_TRIALS_PER_BLOCK,
    MonteCarloResult,
    adaptive_monte_carlo,
    block_seeds,
    minimum_block_size,
    numerical_tolerance,
)
from plansim.uncertainty.metrology.propagation import (
    DEFAULT_COVERAGE_PROBABILITY,
    combine,
    coverage_factor,
    coverage_factors,
    welch_satterthwaite,
)
from plansim.uncertainty.metrology.several_outputs import JointRegionCheck, correlation_matrix, joint_region
from plansim.uncertainty.metrology.validation import ValidationOutcome, validate_gum

__all__ = [
    "COVERAGE_Z",
    "DEFAULT_COVERAGE_PROBABILITY",
    "DEFAULT_DIGITS",
    "DEFAULT_TRIALS_PER_BLOCK",
    "OVERSTATEMENT_FACTOR",
    "JointRegionCheck",
    "MonteCarloResult",
    "ValidationOutcome",
    "adaptive_monte_carlo",
    "block_seeds",
    "combine",
    "correlation_matrix",
    "coverage_against_truth",
    "coverage_factor",
    "coverage_factors",
    "coverage_intervals",
    "coverage_tolerance",
    "coverage_verdict",
    "joint_region",
    "minimum_block_size",
    "minimum_trials_to_judge",
    "numerical_tolerance",
    "validate_gum",
    "welch_satterthwaite",
]
