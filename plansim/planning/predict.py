"""The uncertainty a schedule will give, predicted without a Monte Carlo: :func:`predict`.

The prediction is the GUM (JCGM 100) evaluation of the scenario's actual reduction and design
(:func:`plansim.uncertainty.gum.evaluate_gum`; docs/uncertainty.md), returned as a self-describing
Dataset: its figures alone (:func:`plansim.uncertainty.gum.gum_uncertainties`, the same numbers
without building the 39 budgets behind them). It includes what makes calibration schedules differ:

- **noise floors**: the segment means' noise follows the scenario's noise model, so bias instability
  and rate random walk stop averaging down with dwell (the drift covariance of
  :func:`plansim.uncertainty.drift.drift_covariance`), not σ²/N;
- **table and fixture errors** as inputs shared by every segment of one setting (per position, per
  rate point, per calibration: JJF 2003 Table 1 or the scenario's grade);
- **quantisation** the noise does not dither, as the systematic it is: the segments of a channel share
  the quantiser's offset (:func:`plansim.uncertainty.quantisation.quantisation_covariance`);
- **systematic effects the estimators do not correct** (Earth rate, lever arm, g-sensitivity through
  a tilt, …) as the predicted bias of each parameter (GUM 3.2.4).

Where the GUM holds (a linear reduction, inputs whose combination is close to normal) the predicted
standard uncertainty is the Monte Carlo standard deviation; ``plansim validate`` checks that for a
scenario (JCGM 101), and tests/test_predict.py on five schedules. It does not hold for the
accelerometers of ``jjf2003`` (a 12-bit quantiser that the noise does not dither, offsets spread over a
quarter step): there the Monte Carlo is the reference.
"""

from __future__ import annotations

import functools

import numpy as np
import xarray as xr

from plansim.config import Scenario
from plansim.model.parameters import N_PARAMETERS, PARAMETERS
from plansim.uncertainty.gum import gum_uncertainties


def predict(scenario: Scenario, coverage_probability: float = 0.95) -> xr.Dataset:
    """Predicted standard uncertainty, bias and expanded uncertainty of the 39 parameters of *scenario*.

    Parameters
    ----------
    scenario : plansim.config.Scenario
        The schedule, table, noise, acquisition and reduction (``plansim.load_scenario(name, overrides)``).
    coverage_probability : float
        p of the expanded uncertainty ``U_predicted`` (0 < p < 1; default 0.95).

    Returns
    -------
    xarray.Dataset
        Over ``parameter`` (its ``unit`` and ``long_name`` as coordinates, SI):
        ``u_predicted`` (the standard uncertainty of the calibrated value, u_c), ``bias_predicted``
        (the error at the inputs' expectation: the systematic effects the estimators leave),
        ``U_predicted`` (k·u_c, k from the Welch–Satterthwaite ν_eff), ``coverage_factor``,
        ``effective_dof``; and ``covariance`` (``parameter`` × ``parameter_``) of the errors. Attributes:
        the scenario, its source and overrides, the method.

    Raises
    ------
    TypeError
        *scenario* is not a Scenario.
    ValueError
        *coverage_probability* is not between 0 and 1.

    Examples
    --------
    >>> import plansim
    >>> p = plansim.predict(plansim.load_scenario("jjf2003", ["schedule.dwell=60 s"]))  # doctest: +SKIP
    >>> float(p.u_predicted.sel(parameter="Kgxx"))                                          # doctest: +SKIP
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario (plansim.load_scenario), got {type(scenario).__name__}")
    if not 0 < coverage_probability < 1:
        raise ValueError(f"coverage_probability = {coverage_probability!r}: must be between 0 and 1")
    gum = gum_uncertainties(scenario, coverage_probability=coverage_probability)
    values = {"u_predicted": gum.standard_uncertainty, "bias_predicted": gum.estimate,
              "U_predicted": gum.expanded_uncertainty, "coverage_factor": gum.coverage_factor,
              "effective_dof": gum.effective_dof, "covariance": gum.covariance}
    prediction = _template(float(coverage_probability)).copy(deep=False, data=values)
    prediction.attrs = {
        "title": f"plansim prediction for scenario {scenario.name!r}",
        "scenario": scenario.name, "scenario_source": scenario.source or "a Scenario object built in Python",
        "scenario_overrides": "; ".join(scenario.overrides),
        "method": "GUM (JCGM 100) of the JJF 2003 reduction on the scenario's schedule "
                  "(plansim.uncertainty.gum.evaluate_gum; docs/uncertainty.md)",
        "coverage_probability": float(coverage_probability)}
    return prediction


@functools.lru_cache(maxsize=8)
def _template(coverage_probability: float) -> xr.Dataset:
    """The Dataset :func:`predict` returns, with placeholder figures: built once per *coverage_probability*
    and copied with each prediction's figures (its variables' attributes copied, the coordinates shared,
    read-only), at a quarter of the cost of building it."""
    per = "SI: the unit coordinate of each parameter"
    vector, matrix = np.zeros(N_PARAMETERS), np.zeros((N_PARAMETERS, N_PARAMETERS))
    data = {
        "u_predicted": ("parameter", vector,
                        {"units": per, "long_name": "predicted standard uncertainty u_c of the calibrated value"}),
        "bias_predicted": ("parameter", vector,
                           {"units": per, "long_name": "predicted bias: the error at the inputs' expectation "
                                                       "(systematic effects the estimators do not correct)"}),
        "U_predicted": ("parameter", vector,
                        {"units": per, "long_name": f"predicted expanded uncertainty, p = {coverage_probability:g}"}),
        "coverage_factor": ("parameter", vector,
                            {"units": "1", "long_name": "coverage factor k (t-distribution at nu_eff)"}),
        "effective_dof": ("parameter", vector,
                          {"units": "1", "long_name": "Welch-Satterthwaite effective degrees of freedom"}),
        "covariance": (("parameter", "parameter_"), matrix,
                       {"units": "product of the two parameters' SI units",
                        "long_name": "covariance of the parameter errors (GUM 5.2.2)"}),
    }
    names = [p.name for p in PARAMETERS]
    coordinates = {"parameter": ("parameter", names),
                   "unit": ("parameter", [p.si_unit for p in PARAMETERS]),
                   "long_name": ("parameter", [p.long_name for p in PARAMETERS]),
                   "parameter_": ("parameter_", names)}
    template = xr.Dataset(data, coords=coordinates)
    for name in ("unit", "long_name"):  # shared by every prediction: not to be written in place
        template[name].values.flags.writeable = False
    return template
