"""The GUM of the JJF 1535-2015 items (plansim.uncertainty.jjf1535_gum) and its validation by Monte Carlo
(plansim.uncertainty.jjf1535_validation); docs/jjf1535.md, "The GUM of the schedule"."""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.config import parse_scenario
from plansim.io.scenario_file import load_scenario
from plansim.schedule.jjf1535 import jjf1535_procedure
from plansim.uncertainty.jjf1535_gum import GUM_ITEMS, NOT_PROPAGATED, jjf1535_gum, reduction_jacobian
from plansim.uncertainty.jjf1535_monte_carlo import jjf1535_monte_carlo
from plansim.uncertainty.jjf1535_validation import scatter_tolerance, validate_jjf1535
from plansim.units import DEG, HOUR

ARW = 0.15 * DEG / 60.0  # 0.15 °/√h in rad/√s
#: a short procedure (4 bias periods, a 1-min Allan record, 10-min soaks): the same rate runs as the default
SHORT = {"bias_periods": 4, "allan_duration": 60.0, "soak": 600.0}


def _short():
    return jjf1535_procedure(100 * DEG, **SHORT)


def _rate_runs(procedure):
    """Per room run: the nominal rates Ω_j, their dwells T_j and the slope weights c_j = (Ω_j − Ω̄)/Σ(Ω_k − Ω̄)²."""
    segs = procedure.schedule.segments
    out = []
    for run in procedure.room_runs:
        rates = np.array([segs[k].rate for k in run.points])
        T = np.array([segs[k].samples / segs[k].sample_rate for k in run.points])
        out.append((rates, T, (rates - rates.mean()) / np.sum((rates - rates.mean()) ** 2)))
    return out


def test_u_of_K_and_B0_from_white_noise_is_the_closed_form(ideal_document):
    """White gyro noise only (ARW N = 0.15 °/√h; the ideal world: no table error, no quantiser, no Earth rate).

    K (eq. (5), mean of Q runs): a rate point of T_j seconds has u = N/√T_j; the at-rest output subtracted from
    every point of a run shifts them alike and leaves the slope (Σ c_j = 0), so for one run
    u²(K_q) = Σ c_j² N²/T_j with c_j = (Ω_j − Ω̄)/Σ(Ω_k − Ω̄)²; for equal dwells this is σ_mean/√Σ(Ω_j − Ω̄)².
    The Q runs are independent: u(K) = u(K_q)/√Q.
    B0 (eq. (15)–(17)): B0 = (1/Q) Σ_q F̄_q/K, F̄_q the mean of a record of T_rec seconds, u(F̄_q) = N/√T_rec;
    K is read from other segments (independent), so (Appendix A's model (A.4)) u²(B0) = N²/(Q T_rec K²) +
    (B0/K)² u²(K), B0 the reported bias (y + true value).
    Both are the GUM's figures to 1e-6 (the reduction's Jacobian by central differences: K is linear in the
    means, B0 = F̄/K smooth; the rest is rounding).
    """
    ideal_document["mimu"]["noise"] = {"gyro_angle_random_walk": "0.15 deg/sqrt(h)"}
    scenario = parse_scenario(ideal_document)
    procedure = _short()
    gum = jjf1535_gum(scenario, procedure, keep_table=True)
    runs = _rate_runs(procedure)
    Q = len(runs)
    u_K = math.sqrt(sum(np.sum(c**2 * ARW**2 / T) for _r, T, c in runs)) / Q
    k = gum.items.index("scale_factor")
    assert set(gum.contributions) == {"white noise, gyros"}
    assert gum.standard_uncertainty[k] == pytest.approx(u_K, rel=1e-6)
    K = float(scenario.truth_nominal[0])  # Kg_xx; no temperature coefficient
    segs = procedure.schedule.segments
    T_rec = [sum(segs[s].samples / segs[s].sample_rate for s in record) for record in procedure.room_bias]
    assert len(set(T_rec)) == 1
    b = gum.items.index("bias")
    true_B0 = 0.12 * DEG / K  # Bgx/K (the ideal unit, room temperature = reference)
    B0 = float(gum.estimate[b]) + true_B0
    u_B0 = math.sqrt(ARW**2 / (Q * T_rec[0] * K**2) + (B0 / K) ** 2 * u_K**2)
    assert gum.standard_uncertainty[b] == pytest.approx(u_B0, rel=1e-6)
    # ν_eff: the white noise is type A with ν = n − 1 per segment mean; finite
    assert np.all(np.isfinite(gum.effective_dof[[k, b]])) and np.all(gum.effective_dof[[k, b]] > 2)


def test_u_of_K_from_the_rate_error_acting_once_per_rate_setting(ideal_document):
    """The rate table alone: a relative rate error of ±0.05 % (rectangular, u_r = 5e-4/√3), drawn once per rate
    setting (``rate_error_per_point``), then a systematic one of u_s (normal, common to every setting).

    Per setting: the point j of run q reads K·Ω_j(1 + e_qj); the slope moves by K Σ_j c_j Ω_j e_qj, so
    u(K_q) = K u_r sqrt(Σ_j c_j² Ω_j²) and u(K) = u(K_q)/√Q (independent settings in each run).
    Systematic: every rate is Ω_j(1 + e), the fitted line's slope is K(1 + e): u(K) = K u_s exactly.
    B0's record is at rest: neither moves F̄, but B0 = F̄/K reads K: c = −B0/K.
    """
    K = 1.0021  # the ideal unit's Kg_xx
    ideal_document["turntable"] = {"rate_error_per_point": "0.05 %"}
    scenario = parse_scenario(ideal_document)
    procedure = _short()
    gum = jjf1535_gum(scenario, procedure, keep_table=True)
    runs = _rate_runs(procedure)
    u_r = 5e-4 / math.sqrt(3.0)
    u_K = K * u_r * math.sqrt(sum(np.sum(c**2 * r**2) for r, _T, c in runs)) / len(runs)
    k, b = gum.items.index("scale_factor"), gum.items.index("bias")
    assert gum.contributions["rate error, per point"][k] == pytest.approx(u_K, rel=1e-6)
    B0 = float(gum.estimate[b]) + 0.12 * DEG / K
    assert gum.contributions["rate error, per point"][b] == pytest.approx(abs(B0) / K * u_K, rel=1e-6)

    ideal_document["turntable"] = {"rate_error_systematic": "0.05 %"}
    gum = jjf1535_gum(parse_scenario(ideal_document), procedure, keep_table=True)
    assert gum.contributions["rate error, systematic"][k] == pytest.approx(K * u_r, rel=1e-6)


def test_zero_noise_identity_the_gum_estimate_is_the_monte_carlo_error(ideal_document):
    """The ideal world (nothing uncertain): every u_c is 0 and the GUM's y, the error at the expected means, is
    the error of every Monte Carlo trial, to rounding — including the systematic part eq. (16) does not correct
    (the x gyro's G_xx·g in the axis-up bias record) and the deterministic input staircase (a resolution of
    0.3 °/s moves the rate points of eq. (5) to its steps: K's y is not 0)."""
    ideal_document["mimu"]["effects"] = {"gyro_resolution": ["0.3 deg/s", "0 deg/s", "0 deg/s"]}
    scenario = parse_scenario(ideal_document)
    procedure = _short()
    gum = jjf1535_gum(scenario, procedure, keep_table=True)
    assert np.all(gum.standard_uncertainty == 0.0)
    mc = jjf1535_monte_carlo(scenario, trials=2, seed=5, procedure=procedure, keep_table=True)
    for p, item in enumerate(GUM_ITEMS):
        errors = mc.column(item) - mc.column(item, "truth")
        scale = max(abs(float(mc.column(item, "truth")[0])), 1e-12)
        assert np.allclose(errors, gum.estimate[p], rtol=0, atol=1e-9 * scale), item
    k, b = gum.items.index("scale_factor"), gum.items.index("bias")
    assert abs(gum.estimate[k]) > 1e-4
    # eq. (16) divides the axis-up record's Bg + G_xx·g by the reported K; the true B0 is Bg/K
    K, reported_K = 1.0021, 1.0021 + float(gum.estimate[k])
    g_xx = 18 * DEG / HOUR / 9.80665  # 18 °/h/g in rad/s per m/s²
    want = (0.12 * DEG + g_xx * scenario.environment.gravity) / reported_K - 0.12 * DEG / K
    assert gum.estimate[b] == pytest.approx(want, rel=1e-6)


def test_the_turn_on_bias_enters_B0_once_per_record_and_not_K(ideal_document):
    """σ_on per power cycle (the unit switched off between the Q bias records and between the Q rate runs).
    B0 = (1/Q) Σ F̄_q/K with one turn-on draw per record: u(B0) = σ_on/(K√Q). Each rate run's points and its
    at-rest records share one power cycle, so the subtraction removes the draw from the slope: K has no line."""
    sigma = 5 * DEG / HOUR
    ideal_document["mimu"]["effects"] = {"gyro_turn_on_bias": ["5 deg/h", "0 deg/h", "0 deg/h"]}
    scenario = parse_scenario(ideal_document)
    procedure = _short()
    gum = jjf1535_gum(scenario, procedure, keep_table=True)
    k, b = gum.items.index("scale_factor"), gum.items.index("bias")
    line = gum.contributions["turn-on bias"]
    assert line[b] == pytest.approx(sigma / (1.0021 * math.sqrt(len(procedure.room_bias))), rel=1e-6)
    assert line[k] <= 1e-9 * line[b]


def test_gum_and_monte_carlo_agree_for_the_jjf2003_unit():
    """The jjf2003 unit on the JJF 1535 table (Table 2 grade), the short procedure, 2 blocks of 500 trials
    (seed 1535).

    The Monte Carlo's standard deviation s of M = 1000 errors estimates the GUM's u_c with a relative standard
    error sqrt((2 + κ)/(4M)) (κ the excess kurtosis: 2.2 % for a normal error); ``scatter_agrees`` allows
    3 of them (a false alarm of 0.27 % per item for a correct GUM, 1.6 % for the six; a GUM u_c off by 12 % is
    found with probability > 0.99: (0.12 − 0.067)/0.022 = 2.4 standard errors beyond the limit). The mean error
    lies within 3.29 u_c/√M of the GUM's y (false alarm 1e-3 per item; y is 27 °/h for B0: eq. (16)'s G_xx·g and
    the vertical Earth rate).
    """
    scenario = load_scenario("jjf2003")
    report = validate_jjf1535(scenario, _short(), trials_per_block=500, max_trials=1000, seed=1535)
    M = report.mcm.trials
    assert M == 1000
    for check in report.items:
        assert check.u_ratio_tolerance == pytest.approx(
            scatter_tolerance(M, float(report.mcm.excess_kurtosis[report.gum.items.index(check.item)])))
        assert check.scatter_agrees, (check.item, check.u_ratio, check.u_ratio_tolerance)
        assert abs(check.mcm_y - check.gum_y) <= 3.29 * check.gum_u / math.sqrt(M), check.item
    assert set(report.not_propagated) == set(NOT_PROPAGATED)


def test_scatter_tolerance_is_the_standard_error_of_a_standard_deviation():
    """z·sqrt((2 + κ)/(4M)): for normal values (κ = 0) z/√(2M)."""
    assert scatter_tolerance(800, 0.0) == pytest.approx(3.0 / 40.0)
    assert scatter_tolerance(800, 2.0, z=1.0) == pytest.approx(math.sqrt(4.0 / 3200.0))


@pytest.mark.parametrize("call, error, words", [
    (lambda: jjf1535_gum("jjf2003"), TypeError, ("scenario", "'jjf2003'", "Scenario")),
    (lambda: jjf1535_gum(load_scenario("ideal"), coverage_probability=1.5), ValueError, ("1.5",)),
    (lambda: reduction_jacobian(np.zeros((1, 6)), _short(), 9.8, items=("nonlinearity",)), ValueError,
     ("items", "nonlinearity", "allowed", "scale_factor")),
    (lambda: scatter_tolerance(1, 0.0), ValueError, ("trials", "1", ">= 2")),
    (lambda: scatter_tolerance(10, -3.0), ValueError, ("excess_kurtosis", "-3.0", ">= -2")),
    (lambda: validate_jjf1535(load_scenario("ideal"), tolerance_fraction=0.0), ValueError,
     ("tolerance_fraction", "0.0", "(0, 1]")),
    (lambda: validate_jjf1535(load_scenario("ideal"), seed=-1), ValueError, ("seed", "-1", ">= 0")),
    (lambda: validate_jjf1535("ideal"), TypeError, ("scenario", "'ideal'", "Scenario")),
])
def test_bad_input_is_refused_naming_the_field_the_value_and_what_is_allowed(call, error, words):
    with pytest.raises(error) as info:
        call()
    for word in words:
        assert word in str(info.value), str(info.value)
