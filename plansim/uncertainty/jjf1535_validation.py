"""``plansim validate jjf1535``: the GUM of the JJF 1535-2015 items against an adaptive Monte Carlo (JCGM 101).

:func:`validate_jjf1535` runs, for one unit scenario,

1. the GUM of the items of :data:`~plansim.uncertainty.jjf1535_gum.GUM_ITEMS`
   (:func:`plansim.uncertainty.jjf1535_gum.jjf1535_gum`);
2. the adaptive Monte Carlo method of JCGM 101 7.9.4 on the JJF 1535 session
   (:func:`plansim.uncertainty.jjf1535_monte_carlo.jjf1535_monte_carlo`, one block of trials per block seed), run to
   a fraction (default 1/5, JCGM 101 8.2) of ``δ`` of the GUM ``u_c``, as ``plansim validate`` does for JJF 2003
   (:mod:`plansim.uncertainty.validation`);
3. per item, JCGM 101 8.1: ``d_low = |y − U_p − y_low|``, ``d_high = |y + U_p − y_high|`` against ``δ``
   (:func:`plansim.uncertainty.metrology.validate_gum`), and the ratio of the Monte Carlo's standard deviation of
   the error to the GUM ``u_c`` with its sampling tolerance: for M trials the sample standard deviation has a
   relative standard error ``sqrt((2 + κ)/(4M))`` (κ the excess kurtosis of the errors; ``1/sqrt(2M)`` for a
   normal error), and the ratio agrees if it is within :data:`~plansim.uncertainty.metrology.COVERAGE_Z` (3) of
   them of 1;
4. the coverage of the truth by the GUM ``U95`` (:func:`plansim.uncertainty.metrology.coverage_against_truth`,
   :func:`~plansim.uncertainty.metrology.coverage_verdict`).

The text and JSON of the report are :mod:`plansim.report.validation` (:func:`~plansim.report.validation.jjf1535_json`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.estimate.jjf1535_items import ITEMS
from plansim.schedule.jjf1535 import Jjf1535Procedure
from plansim.uncertainty.jjf1535_gum import GUM_ITEMS, NOT_PROPAGATED, Jjf1535Gum, jjf1535_gum
from plansim.uncertainty.jjf1535_monte_carlo import jjf1535_monte_carlo, jjf1535_scenario
from plansim.uncertainty.metrology.coverage import COVERAGE_Z, coverage_against_truth, coverage_verdict
from plansim.uncertainty.metrology.monte_carlo import (
    DEFAULT_DIGITS,
    DEFAULT_TRIALS_PER_BLOCK,
    MonteCarloResult,
    adaptive_monte_carlo,
    numerical_tolerance,
)
from plansim.uncertainty.metrology.validation import validate_gum
from plansim.uncertainty.validation import DEFAULT_MAX_TRIALS, DEFAULT_TOLERANCE_FRACTION

__all__ = ["Jjf1535ItemValidation", "Jjf1535ValidationReport", "scatter_tolerance", "validate_jjf1535"]


def scatter_tolerance(trials: int, excess_kurtosis: float, z: float = COVERAGE_Z) -> float:
    """``z·sqrt((2 + κ)/(4M))``: *z* standard errors of the ratio s/σ of a sample standard deviation.

    For M values with excess kurtosis κ the large-M variance of s² is ``σ⁴(2/(M − 1) + κ/M)``; the square root
    halves the relative standard error, ``sqrt((2 + κ)/(4M))`` (``1/sqrt(2M)`` for normal values).

    Parameters
    ----------
    trials : int
        M, >= 2.
    excess_kurtosis : float
        κ of the values, >= −2.
    z : float
        Standard errors allowed (default :data:`~plansim.uncertainty.metrology.COVERAGE_Z`, 3).

    Returns
    -------
    float
        The half-width of the band about 1 in which MCM u / GUM u_c agrees.

    Raises
    ------
    ValueError
        *trials* not a whole number >= 2, or κ not finite or below −2.
    """
    if isinstance(trials, bool) or not isinstance(trials, (int, np.integer)) or trials < 2:
        raise ValueError(f"trials = {trials!r}: expected a whole number >= 2")
    kappa = float(excess_kurtosis)
    if not math.isfinite(kappa) or kappa < -2.0:
        raise ValueError(f"excess_kurtosis = {excess_kurtosis!r}: must be finite and >= -2")
    return float(z) * math.sqrt((2.0 + kappa) / (4.0 * trials))


@dataclass(frozen=True)
class Jjf1535ItemValidation:
    """GUM against Monte Carlo for one JJF 1535 item; every figure SI (``unit_si`` is one ``unit`` in SI)."""

    item: str
    clause: str
    unit: str
    unit_si: float
    gum_y: float
    gum_u: float
    gum_dof: float
    gum_k: float
    gum_U95: float
    mcm_y: float
    mcm_u: float
    mcm_low: float
    mcm_high: float
    delta: float
    d_low: float
    d_high: float
    validated: bool
    u_ratio: float
    u_ratio_tolerance: float
    scatter_agrees: bool
    coverage_gum: float
    coverage_verdict: str
    dominant_inputs: tuple[str, ...]

    def as_dict(self) -> dict:
        d = dataclasses.asdict(self)
        d["dominant_inputs"] = list(self.dominant_inputs)
        return d


@dataclass(frozen=True)
class Jjf1535ValidationReport:
    """Everything :func:`validate_jjf1535` found (module docstring)."""

    unit_scenario: str
    description: str
    gum: Jjf1535Gum
    mcm: MonteCarloResult
    items: tuple[Jjf1535ItemValidation, ...]
    digits: int
    tolerance_fraction: float
    path: str
    not_propagated: dict

    def item(self, name: str) -> Jjf1535ItemValidation:
        """The validation of item *name*."""
        for check in self.items:
            if check.item == name:
                return check
        raise ValueError(f"item = {name!r}; allowed: {', '.join(c.item for c in self.items)}")


def _dominant(gum: Jjf1535Gum, item: str, count: int = 2) -> tuple[str, ...]:
    budget = gum.item(item)
    uc = budget["u_c"]
    if uc <= 0:
        return ()
    return tuple(f"{line['name']} ({(line['u_i'] / uc) ** 2:.0%})" for line in budget["inputs"][:count])


def validate_jjf1535(scenario: Scenario, procedure: Jjf1535Procedure | None = None, *, digits: int = DEFAULT_DIGITS,
                     trials_per_block: int = DEFAULT_TRIALS_PER_BLOCK, max_trials: int = DEFAULT_MAX_TRIALS,
                     seed: int | None = None, tolerance_fraction: float = DEFAULT_TOLERANCE_FRACTION,
                     path: str = "auto", coverage_probability: float = 0.95,
                     progress: Callable[[int, int, float], None] | None = None) -> Jjf1535ValidationReport:
    """The GUM of the JJF 1535 items of *scenario*'s gyro against the adaptive Monte Carlo (module docstring).

    Parameters
    ----------
    scenario : Scenario
        The unit scenario (its unit, noise, effects, laboratory; the JJF 1535 procedure, table and acquisition
        replace its own, :func:`~plansim.uncertainty.jjf1535_monte_carlo.jjf1535_scenario`).
    procedure : Jjf1535Procedure, optional
        Default: :func:`~plansim.schedule.jjf1535.jjf1535_procedure` up to 100 °/s.
    digits, trials_per_block, max_trials
        ``n_dig``, ``M`` and the upper limit of the adaptive procedure
        (:func:`plansim.uncertainty.metrology.adaptive_monte_carlo`).
    seed : int, optional
        Root seed of the block seeds (default the scenario's).
    tolerance_fraction : float
        Run until ``2s ≤ fraction·δ`` of the GUM ``u_c`` (JCGM 101 8.2: 1/5), in (0, 1].
    path : {"auto", "sample", "segment"}
        Simulation path.
    coverage_probability : float
        ``p`` (0.95).
    progress : callable, optional
        ``progress(trials_done, blocks, worst)`` after each block.

    Returns
    -------
    Jjf1535ValidationReport

    Raises
    ------
    TypeError
        *scenario* is not a Scenario.
    ValueError
        A bad tolerance fraction or seed, a bad argument of the adaptive procedure; a unit without any uncertain
        input (every GUM ``u_c`` 0), before any simulation.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    if isinstance(tolerance_fraction, bool) or not isinstance(tolerance_fraction, (int, float)) \
            or not 0.0 < tolerance_fraction <= 1.0:
        raise ValueError(f"tolerance_fraction = {tolerance_fraction!r}: must lie in (0, 1] (JCGM 101 8.2 uses 1/5)")
    seed = scenario.seed if seed is None else seed
    if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
        raise ValueError(f"seed = {seed!r}: expected a whole number >= 0")
    _world, procedure = jjf1535_scenario(scenario, procedure)  # refuses a unit the procedure would clip, first
    gum = jjf1535_gum(scenario, procedure, coverage_probability)
    u_gum = gum.standard_uncertainty
    if not np.all(u_gum > 0):
        zero = [item for item, u in zip(gum.items, u_gum) if not u > 0]
        raise ValueError(f"unit scenario {scenario.name!r}: nothing to validate for {', '.join(zero)} — no input "
                         "of the JJF 1535 session moves it (GUM u_c = 0), so a Monte Carlo would only see round-off; "
                         "'plansim run jjf1535' shows its errors")
    columns = [list(ITEMS).index(item) for item in GUM_ITEMS]
    chosen = []

    def simulate(trials: int, block_seed: int) -> np.ndarray:
        result = jjf1535_monte_carlo(scenario, trials, block_seed, procedure=procedure, path=path)
        chosen.append(result.path)
        return result.values[:, columns] - result.truth[:, columns]

    mc = adaptive_monte_carlo(simulate, GUM_ITEMS, seed=seed, digits=digits, trials_per_block=trials_per_block,
                              max_trials=max_trials, tolerance=tolerance_fraction * numerical_tolerance(u_gum, digits),
                              coverage_probability=coverage_probability, progress=progress)
    outcome = validate_gum(gum.estimate, gum.expanded_uncertainty, u_gum, mc.low, mc.high, digits)
    errors = mc.values
    covered = coverage_against_truth(errors, gum.expanded_uncertainty)
    checks = []
    for p, item in enumerate(GUM_ITEMS):
        clause, _equations, unit, scale = ITEMS[item]
        needed = float(np.quantile(np.abs(errors[:, p]), coverage_probability))
        verdict, _factor = coverage_verdict(float(covered[p]), errors.shape[0], coverage_probability,
                                            float(gum.expanded_uncertainty[p]), needed)
        ratio = float(mc.standard_uncertainty[p] / u_gum[p])
        tolerance = scatter_tolerance(errors.shape[0], float(mc.excess_kurtosis[p]))
        checks.append(Jjf1535ItemValidation(
            item=item, clause=clause, unit=unit, unit_si=scale, gum_y=float(gum.estimate[p]), gum_u=float(u_gum[p]),
            gum_dof=float(gum.effective_dof[p]), gum_k=float(gum.coverage_factor[p]),
            gum_U95=float(gum.expanded_uncertainty[p]), mcm_y=float(mc.estimate[p]),
            mcm_u=float(mc.standard_uncertainty[p]), mcm_low=float(mc.low[p]), mcm_high=float(mc.high[p]),
            delta=float(outcome.delta[p]), d_low=float(outcome.d_low[p]), d_high=float(outcome.d_high[p]),
            validated=bool(outcome.validated[p]), u_ratio=ratio, u_ratio_tolerance=tolerance,
            scatter_agrees=abs(ratio - 1.0) <= tolerance, coverage_gum=float(covered[p]), coverage_verdict=verdict,
            dominant_inputs=_dominant(gum, item)))
    return Jjf1535ValidationReport(
        unit_scenario=scenario.name, description=scenario.description, gum=gum, mcm=mc, items=tuple(checks),
        digits=int(digits), tolerance_fraction=float(tolerance_fraction), path=chosen[0] if chosen else path,
        not_propagated=dict(NOT_PROPAGATED))
