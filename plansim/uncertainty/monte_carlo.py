"""The adaptive Monte Carlo (JCGM 101 7.9.4) of a scenario's calibration: outputs are the errors of the 39 parameters.

Each Monte Carlo trial is one simulated calibration, whose inputs — the unit's true parameters,
every table and fixture error, noise, drift, quantisation — are drawn from the scenario's
distributions, and whose output is the error ``E = Ŷ − Y`` of each JJF 2003 parameter (the output
quantity of the GUM budgets of :mod:`plansim.uncertainty.gum`). The simulation is passed in as a
callable ``simulate(trials, seed) -> (trials, 39)`` (the runner supplies it), so this layer never
imports the runner; the procedure itself is :mod:`plansim.uncertainty.metrology.monte_carlo`.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from plansim.config import Scenario
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS
from plansim.uncertainty.metrology.monte_carlo import (
    DEFAULT_DIGITS,
    DEFAULT_TRIALS_PER_BLOCK,
    MonteCarloResult,
    ProgressCallback,
    Simulate,
    adaptive_monte_carlo,
)
from plansim.uncertainty.metrology.several_outputs import JointRegionCheck, joint_region

__all__ = ["KG_PARAMETERS", "CalibrationMonteCarlo", "calibration_monte_carlo", "joint_region_check"]

#: The nine elements of Kg, checked jointly (JCGM 102).
KG_PARAMETERS = tuple(p.name for p in PARAMETERS if p.group == "Kg")


@dataclass(frozen=True)
class CalibrationMonteCarlo(MonteCarloResult):
    """:class:`~plansim.uncertainty.metrology.MonteCarloResult` of a scenario's calibration.

    The outputs (``names``) are the 39 parameters of :data:`plansim.model.parameters.PARAMETER_NAMES`,
    the values their errors ``estimate − truth`` (SI).

    Attributes
    ----------
    scenario : str
        Scenario name.
    path : str
        The simulation path that produced the values (for the report).
    """

    scenario: str = ""
    path: str = ""

    @property
    def errors(self) -> np.ndarray:
        """(h·M, 39): every Monte Carlo error, estimate − truth, SI."""
        return self.values


def _check_parameter_names(parameters) -> None:
    """Unknown names are named as parameters (the core calls them outputs)."""
    if parameters is None or isinstance(parameters, str) or not isinstance(parameters, Sequence):
        return  # None: all; a wrong type is the core's TypeError
    for name in parameters:
        if name not in PARAMETER_INDEX:
            raise ValueError(f"parameters: unknown parameter {name!r}; known: {', '.join(PARAMETER_NAMES)}")


def calibration_monte_carlo(simulate: Simulate, scenario: Scenario, *, path: str = "", digits: int = DEFAULT_DIGITS,
                            trials_per_block: int = DEFAULT_TRIALS_PER_BLOCK, max_trials: int = 1_000_000,
                            seed: int | None = None, tolerance=None, parameters: Sequence[str] | None = None,
                            coverage_probability: float = 0.95,
                            progress: ProgressCallback | None = None) -> CalibrationMonteCarlo:
    """Adaptive Monte Carlo procedure of JCGM 101 7.9.4 on a scenario's simulated calibration.

    Parameters
    ----------
    simulate : callable
        ``simulate(trials, seed) -> (trials, 39)`` errors of the scenario's calibration.
    scenario : Scenario
        The scenario simulated (its name and default seed).
    path : str
        Name of the simulation path *simulate* takes, for the report.
    digits, trials_per_block, max_trials, tolerance, coverage_probability, progress
        As in :func:`plansim.uncertainty.metrology.adaptive_monte_carlo`.
    seed : int, optional
        Root seed of the block seeds; default the scenario's.
    parameters : sequence of str, optional
        The parameters whose numerical tolerance decides the stop (default all 39).

    Returns
    -------
    CalibrationMonteCarlo
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    _check_parameter_names(parameters)
    result = adaptive_monte_carlo(
        simulate, PARAMETER_NAMES, seed=scenario.seed if seed is None else seed, digits=digits,
        trials_per_block=trials_per_block, max_trials=max_trials, tolerance=tolerance, monitor=parameters,
        coverage_probability=coverage_probability, progress=progress)
    fields = {f.name: getattr(result, f.name) for f in dataclasses.fields(MonteCarloResult)}
    return CalibrationMonteCarlo(**fields, scenario=scenario.name, path=path)


def joint_region_check(values, parameters: Sequence[str], coverage_probability: float = 0.95,
                       gum_covariance=None, marginal_k: float = 2.0) -> JointRegionCheck:
    """Several parameters jointly (JCGM 102 7.7, 6.5): ellipsoid versus the box of marginal intervals.

    :func:`plansim.uncertainty.metrology.joint_region` on the 39 parameters.

    Parameters
    ----------
    values : (M, 39) array_like
        Monte Carlo errors of all parameters.
    parameters : sequence of str
        The parameters considered together (e.g. :data:`KG_PARAMETERS`).
    coverage_probability : float
        ``p``.
    gum_covariance : (39, 39) array_like, optional
        The GUM covariance of the errors, for the coverage of the truth by the GUM ellipsoid.
    marginal_k : float
        ``k`` of the marginal intervals a certificate prints (2).
    """
    _check_parameter_names(list(parameters))
    return joint_region(values, parameters, PARAMETER_NAMES, coverage_probability, gum_covariance, marginal_k)
