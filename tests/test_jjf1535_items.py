"""JJF 1535 items from a simulated session (plansim.estimate.jjf1535_items): the zero-noise identity of every item
with a true value, and what the axis-up bias record takes in besides the bias."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from plansim.config import parse_scenario
from plansim.estimate.jjf1535_items import ITEMS, reduce_items, true_items
from plansim.model.environment import EARTH_RATE
from plansim.model.parameters import unpack
from plansim.schedule.jjf1535 import jjf1535_procedure
from plansim.simulate.chunks import simulate_recording
from plansim.units import DEG

PPM = 1e-6
KAPPA = 80 * PPM  # 1/°C
BETA = 0.02 * DEG / 3600  # 0.02 °/h/°C in rad/s/°C
ALPHA = 300 * PPM


def _session(document, procedure, **effects):
    scenario = parse_scenario(document)
    scenario = dataclasses.replace(scenario, schedule=procedure.schedule,
                                   effects=dataclasses.replace(scenario.effects, **effects))
    _samples, means, truth = simulate_recording(scenario, seed=3, trial=0)
    return scenario, means, truth


def _small():
    return jjf1535_procedure(100 * DEG, bias_periods=4, allan_duration=60.0, soak=600.0)


@pytest.mark.parametrize("reference_temperature", [20.0, 25.0])
def test_zero_noise_identity(ideal_document, reference_temperature):
    """The ideal world (no noise, no table error, no Earth rate, no quantisation) with temperature coefficients
    and an asymmetry on the x gyro: every item with a true value comes back to round-off, except eq. (15)–(17)'s
    bias, whose axis-up record also holds G[x, x]·g (checked below by hand: offset = G[x, x]·g/K), and the
    threshold and resolution of a unit without a dead zone or resolution (truth 0), which the procedure reports as
    its smallest tested rate (the JJF 1535 effects themselves: tests/test_jjf1535_effects.py)."""
    procedure = _small()
    zeros = np.zeros(3)
    scenario, means, truth = _session(
        ideal_document, procedure,
        gyro_scale_temperature_coefficient=np.array([KAPPA, 0, 0]),
        gyro_bias_temperature_coefficient=np.array([BETA, 0, 0]),
        gyro_asymmetry=np.array([ALPHA, 0, 0]), gyro_nonlinearity_quadratic=zeros, gyro_nonlinearity_cubic=zeros,
        reference_temperature=reference_temperature)
    g = scenario.environment.gravity
    got = reduce_items(means, procedure, g)
    want = true_items(truth, procedure, scale_temperature_coefficient=KAPPA, bias_temperature_coefficient=BETA,
                      reference_temperature=reference_temperature, asymmetry=ALPHA)
    assert set(got) == set(want) == set(ITEMS)
    p = unpack(truth)
    K = p["Kg"][0, 0] * (1 + KAPPA * (20.0 - reference_temperature))
    assert want["scale_factor"] == pytest.approx(K, rel=1e-15)
    # K± = K ± ½·α·Kg[x, x] through the origin (the asymmetry term is on the reference-temperature Kg): α·Kg/K
    assert want["asymmetry"] == pytest.approx(ALPHA * p["Kg"][0, 0] / K, rel=1e-9)
    for item in ITEMS:
        if item == "bias_stability":
            assert math.isnan(want[item]) and got[item] == pytest.approx(0.0, abs=1e-15)
            continue
        expected = want[item] + (p["G"][0, 0] * g / K if item == "bias" else 0.0)
        if item in ("threshold", "resolution"):
            # no dead zone or resolution (truth 0): the procedure reports its smallest tested rate (increment)
            assert want[item] == 0.0
            expected = procedure.resolution_increments[-1]
        scale = ITEMS[item][3]
        tolerance = 1e-12 if item == "scale_repeatability" else 1e-9 * scale  # eq. (10) of three equal K: round-off
        assert abs(got[item] - expected) <= tolerance + 1e-12 * abs(expected), item


def test_earth_rate_enters_the_axis_up_bias_and_the_x_g_sensitivity(ideal_document):
    """With the Earth rate on, x up at heading 0 puts body y East and z North: the x gyro senses
    Kg[x, x]·Ω sin φ + Kg[x, z]·Ω cos φ; x down flips both. So eq. (16) reads (that + G[x, x]·g)/K above Bg/K,
    the x g-sensitivity reads that/(g·K) above G[x, x]/K, and the up/down mean cancels it (round-off)."""
    ideal_document["environment"]["earth_rate"] = True
    procedure = _small()
    scenario, means, truth = _session(ideal_document, procedure)
    g, lat = scenario.environment.gravity, scenario.environment.latitude
    got = reduce_items(means, procedure, g)
    want = true_items(truth, procedure)
    p = unpack(truth)
    K = p["Kg"][0, 0]
    earth = p["Kg"][0, 0] * EARTH_RATE * math.sin(lat) + p["Kg"][0, 2] * EARTH_RATE * math.cos(lat)
    assert got["bias"] - want["bias"] == pytest.approx((earth + p["G"][0, 0] * g) / K, rel=1e-9)
    assert got["g_sensitivity_x"] - want["g_sensitivity_x"] == pytest.approx(earth / (g * K), rel=1e-9)
    assert got["bias_up_down"] == pytest.approx(want["bias_up_down"], rel=1e-12)
    # y and z up/down keep the x gyro East–West, so only its cross-couplings see the Earth rate flip: ±y up
    # (heading 90°: z stays North in both) leaves Kg[x, y]·Ω sin φ; ±z up (y North, then −North) leaves
    # Kg[x, z]·Ω sin φ + Kg[x, y]·Ω cos φ
    assert got["g_sensitivity_y"] - want["g_sensitivity_y"] == pytest.approx(
        p["Kg"][0, 1] * EARTH_RATE * math.sin(lat) / (g * K), rel=1e-6)
    assert got["g_sensitivity_z"] - want["g_sensitivity_z"] == pytest.approx(
        (p["Kg"][0, 2] * math.sin(lat) + p["Kg"][0, 1] * math.cos(lat)) * EARTH_RATE / (g * K), rel=1e-6)


def test_nonlinearity_of_a_quadratic_response():
    """n2 = 1e-4 per rad/s on K = 1 over rates ±Ω_j: F = Ω + n2·Ω². The line fit of an even function over
    symmetric rates has slope 1 and intercept n2·mean(Ω²); the largest residual is at ±Ω_max:
    n2·(Ω_max² − mean(Ω²)); eq. (6) divides by K·2Ω_max."""
    procedure = _small()
    n2 = 1e-4
    truth = np.zeros(39)
    truth[0] = 1.0
    got = true_items(truth, procedure, nonlinearity_quadratic=n2)
    rates = np.array([procedure.schedule.segments[k].rate for k in procedure.room_runs[0].points])
    wmax = rates.max()
    resid = n2 * np.abs(rates**2 - np.mean(rates**2)).max()
    assert resid == pytest.approx(n2 * (wmax**2 - np.mean(rates**2)))
    assert got["nonlinearity"] == pytest.approx(resid / (2 * wmax), rel=1e-9)


def test_bad_input():
    procedure = _small()
    with pytest.raises(ValueError, match=r"means: expected shape"):
        reduce_items(np.zeros((3, 6)), procedure, 9.8)
    with pytest.raises(TypeError, match="procedure"):
        reduce_items(np.zeros((3, 6)), procedure.schedule, 9.8)
