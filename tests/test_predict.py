"""plansim.predict: the GUM prediction of a schedule's uncertainty, against the Monte Carlo on five schedules."""

from __future__ import annotations

import numpy as np
import pytest

import plansim
from plansim.io.scenario_file import load_scenario
from plansim.model.parameters import PARAMETER_NAMES
from plansim.runner import run

Z = 5.0  # standard errors allowed (as tests/test_gum.py)
TRIALS = 4000

#: five schedules of the linear_gaussian scenario (white noise, normal table errors: the GUM holds), varied
#: as a sweep varies them
SCHEDULES = [
    (),
    ("schedule.positions=6",),
    ("schedule.dwell=10 s",),
    ("schedule.dwell=120 s", "schedule.positions=6"),
    ('schedule.rate_points=["-100 deg/s", "-20 deg/s", "0 deg/s", "20 deg/s", "100 deg/s"]',),
]


def _kurtosis(e):
    c = e - e.mean(axis=0)
    return np.mean(c**4, axis=0) / np.mean(c**2, axis=0) ** 2


@pytest.mark.parametrize("overrides", SCHEDULES, ids=lambda o: "; ".join(o) or "default")
def test_predicted_u_and_bias_are_the_monte_carlo(overrides):
    """The predicted u of all 39 parameters against the Monte Carlo standard deviation (4000 trials), within
    Z·sqrt((β₂ − 1)/(4n)) relative (the standard error of a standard deviation, β₂ the kurtosis; Z = 5, so a
    correct prediction fails with probability below 1e-5 per parameter); the predicted bias against the mean error
    within Z standard errors of the mean."""
    scenario = load_scenario("linear_gaussian", overrides)
    p = plansim.predict(scenario)
    e = run(scenario, trials=TRIALS, seed=11, path="segment")["error"].values
    s = e.std(axis=0, ddof=1)
    u = p.u_predicted.values
    tolerance = Z * np.sqrt((_kurtosis(e) - 1) / (4 * TRIALS))
    bad = {PARAMETER_NAMES[k]: s[k] / u[k] for k in range(39) if abs(s[k] / u[k] - 1) > tolerance[k]}
    assert not bad, bad
    bias = p.bias_predicted.values
    off = {PARAMETER_NAMES[k]: (e[:, k].mean(), bias[k]) for k in range(39)
           if abs(e[:, k].mean() - bias[k]) > Z * s[k] / np.sqrt(TRIALS)}
    assert not off, off


def test_the_prediction_is_a_self_describing_dataset():
    p = plansim.predict(load_scenario("jjf2003", ["schedule.dwell=60 s"]))
    assert list(p.parameter.values) == list(PARAMETER_NAMES)
    assert p.unit.sel(parameter="Bgx").item() == "rad/s"
    for name in ("u_predicted", "bias_predicted", "U_predicted", "coverage_factor", "effective_dof", "covariance"):
        assert p[name].attrs["long_name"] and p[name].attrs["units"]
    assert np.allclose(np.sqrt(np.diag(p.covariance.values)), p.u_predicted.values, rtol=1e-6)
    assert np.all(p.U_predicted.values >= 1.95 * p.u_predicted.values)
    assert p.attrs["scenario_overrides"] == "schedule.dwell=60 s"
    # longer dwell: the white part of the gyro bias averages down (its floor, bias instability, does not)
    short = plansim.predict(load_scenario("jjf2003", ["schedule.dwell=10 s"]))
    assert float(p.u_predicted.sel(parameter="Bgx")) < float(short.u_predicted.sel(parameter="Bgx"))
    with pytest.raises(TypeError, match="expected a plansim Scenario"):
        plansim.predict("jjf2003")
    with pytest.raises(ValueError, match="coverage_probability = 1.5"):
        plansim.predict(load_scenario("ideal"), coverage_probability=1.5)
