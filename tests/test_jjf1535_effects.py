"""The JJF 1535 effects (plansim.model.jjf1535_effects, plansim.simulate.jjf1535_effects): hand-worked formulas, the
zero-noise identity of threshold (eq. (12)–(13)), resolution (eq. (14)), warm-up time (7.2.9) and bias repeatability
(eq. (20)), the effects-off results bit for bit those from before the effects existed, and bad input."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pytest

from plansim import cli
from plansim.config import parse_scenario
from plansim.estimate.jjf1535_items import reduce_items, true_items
from plansim.model.environment import EARTH_RATE
from plansim.model.jjf1535_effects import exponential_segment_mean, input_response
from plansim.model.parameters import unpack
from plansim.report.jjf1535 import GROUPS, items_json, items_table
from plansim.runner import jjf1535_run
from plansim.schedule.jjf1535 import jjf1535_procedure
from plansim.simulate.chunks import simulate_recording
from plansim.simulate.jjf1535_effects import TURN_ON_STREAM, apply_jjf1535_effects, input_axis_rates
from plansim.uncertainty.jjf1535_monte_carlo import Jjf1535MonteCarlo
from plansim.units import DEG, HOUR

DEG_H = DEG / HOUR

#: ``jjf1535_run("jjf2003", trials=2, seed=20151)``'s first two trials as commit f784c7a (before the JJF 1535
#: effects and the 7.2.6/7.2.7/7.2.9 segments existed) computed them: every earlier item, bit for bit
BEFORE = {
    "scale_factor": (1.004398559382946, 1.001619593154283),
    "nonlinearity": (4.1710978391085934e-05, 7.160766616194702e-05),
    "asymmetry": (4.914758275239726e-05, 0.00012160649807823725),
    "scale_temperature_sensitivity": (2.4241539228085674e-06, 2.3797445764282312e-06),
    "bias": (0.0027125247709257456, 0.0011884222508100125),
    "bias_up_down": (0.0025962166907248807, 0.0010437396424346525),
    "bias_stability": (1.5648695900548788e-05, 1.7221480657309286e-05),
    "g_sensitivity_x": (1.4736077540934051e-05, 1.3504321087794583e-05),
    "g_sensitivity_y": (-3.7673426677482577e-06, -5.567126662240212e-06),
    "g_sensitivity_z": (3.999027492344472e-06, 2.984849547768185e-06),
    "g_sensitivity": (1.4736077540934051e-05, 1.3504321087794583e-05),
    "bias_temperature_sensitivity": (1.8355857606223514e-07, 2.606599235967699e-07),
}


def _x(value: float) -> np.ndarray:
    return np.array([value, 0.0, 0.0])


def _noise_free(ideal_document, procedure, seed: int = 7, trial: int = 0, **effects):
    """One noise-free session of the ideal unit (Earth rate off) written by hand: the x gyro's segment means are
    Kg[x, x]·w + Bg[x] (w the commanded rate on its input axis), then the JJF 1535 effects of *effects* (x gyro)."""
    scenario = parse_scenario(ideal_document)
    scenario = dataclasses.replace(scenario, effects=dataclasses.replace(
        scenario.effects, **{name: _x(value) for name, value in effects.items()}))
    truth = scenario.truth_nominal
    p = unpack(truth)
    means = np.zeros((len(procedure.schedule), 6))
    means[:, 0] = p["Kg"][0, 0] * input_axis_rates(scenario, procedure) + p["Bg"][0]
    means = apply_jjf1535_effects(means, truth, scenario, procedure, seed, trial)
    got = reduce_items(means, procedure, scenario.environment.gravity)
    want = true_items(truth, procedure, **{name.removeprefix("gyro_"): value for name, value in effects.items()})
    return got, want, p["Kg"][0, 0]


def test_input_response_hand_worked():
    """A dead zone of 0.01 rad/s: 0.005 and −0.0099 give nothing, 0.01 and −0.02 pass. A resolution of 0.01:
    the mid-tread staircase 0.01·floor(w/0.01 + ½) reads 0.004 → 0, 0.005 → 0.01, 0.016 → 0.02, −0.016 → −0.02,
    −0.005 → 0 (half-way goes up). Both: the dead zone first (0.011 below d = 0.012 → 0; 0.012 → 0.01)."""
    assert input_response([0.005, -0.0099, 0.01, -0.02], 0.01, 0.0).tolist() == [0.0, 0.0, 0.01, -0.02]
    got = input_response([0.004, 0.005, 0.016, -0.016, -0.005], 0.0, 0.01)
    assert got == pytest.approx([0.0, 0.01, 0.02, -0.02, 0.0], abs=1e-15)
    assert input_response([0.011, 0.012], 0.012, 0.01) == pytest.approx([0.0, 0.01], abs=1e-15)
    assert input_response([0.3, -0.7], 0.0, 0.0).tolist() == [0.3, -0.7]


def test_exponential_segment_mean_hand_worked():
    """A·exp(−t/τ) with A = 1, τ = 1 s over two samples 1 s apart from t = 0: (1 + e⁻¹)/2; one sample at t = 3 s:
    e⁻³; A = 100 °/h, τ = 120 s, 30 samples at 1 Hz from t = 17 s: the plain sum."""
    assert exponential_segment_mean(0.0, 2, 1.0, 1.0, 1.0) == pytest.approx((1 + math.exp(-1)) / 2, rel=1e-15)
    assert exponential_segment_mean(3.0, 1, 1.0, 1.0, 1.0) == pytest.approx(math.exp(-3), rel=1e-15)
    A, tau, t = 100 * DEG_H, 120.0, 17.0 + np.arange(30)
    assert exponential_segment_mean(17.0, 30, 1.0, A, tau) == pytest.approx(np.mean(A * np.exp(-t / tau)), rel=1e-13)
    assert exponential_segment_mean([1.0, 2.0], 5, 1.0, 0.0, 0.0).tolist() == [0.0, 0.0]


@pytest.mark.parametrize(("dead_zone", "reported"), [(0.01, 0.01), (0.0063, 0.0063), (0.008, 0.01)])
def test_threshold_zero_noise_identity(ideal_document, dead_zone, reported):
    """Eq. (12)–(13) on a unit with a dead zone d (°/s): at a tested rate |Ω| ≥ d the output less the zero-rate
    output is K·Ω (0 % off F* = K·Ω), below d it is 0 (100 % off), so going down the R5 rates 0.1 … 0.001 °/s the
    last rate within 50 % is the smallest tested one ≥ d: d itself when d is tested (0.01, 0.0063), else the next
    tested rate above it (0.008 → 0.01). The truth is d."""
    got, want, _kg = _noise_free(ideal_document, jjf1535_procedure(100 * DEG), gyro_dead_zone=dead_zone * DEG)
    assert want["threshold"] == dead_zone * DEG
    assert got["threshold"] == reported * DEG


def test_a_threshold_above_every_tested_rate_is_undetermined(ideal_document):
    """A dead zone of 0.2 °/s, above the largest threshold rate (0.1 °/s): every rate of both directions reads 0,
    eq. (13) fails at the first, and the threshold is NaN (undetermined), whichever direction fails."""
    got, want, _kg = _noise_free(ideal_document, jjf1535_procedure(100 * DEG), gyro_dead_zone=0.2 * DEG)
    assert math.isnan(got["threshold"]) and want["threshold"] == 0.2 * DEG
    got, _want, _kg = _noise_free(ideal_document, jjf1535_procedure(100 * DEG), gyro_dead_zone=0.0)
    assert got["threshold"] == 0.001 * DEG  # none: the smallest tested rate
    # with the Earth rate's vertical component E (0.0027 °/s) and d = 0.1 °/s + E/2, the + direction senses
    # 0.1 + E >= d and reports 0.1 °/s, the − direction senses 0.1 − E < d at every rate: undetermined, so the
    # threshold is (the second direction's NaN is not dropped by taking the larger)
    ideal_document["environment"]["earth_rate"] = True
    vertical = EARTH_RATE * math.sin(parse_scenario(ideal_document).environment.latitude)
    got, _want, _kg = _noise_free(ideal_document, jjf1535_procedure(100 * DEG),
                                  gyro_dead_zone=0.1 * DEG + vertical / 2)
    assert math.isnan(got["threshold"])


def test_the_summary_counts_undetermined_trials_and_reports_the_others():
    """Three trials of a threshold, one undetermined (NaN): the row says 1/3 and its statistics are those of the
    other two (mean error (0.01 + 0.016)/2 − 0.005 °/s); the text report and the JSON say so too."""
    items = ("threshold",)
    values = np.array([[0.01], [np.nan], [0.016]]) * DEG
    truth = np.full((3, 1), 0.005 * DEG)
    result = Jjf1535MonteCarlo("unit", 3, 1, "segment", items, values, truth)
    row = result.summary()[0]
    assert row["undetermined"] == pytest.approx(1 / 3)
    assert row["mean_error"] == pytest.approx(0.013 - 0.005) and row["mean"] == pytest.approx(0.013)
    assert items_json([row])[0]["undetermined"] == pytest.approx(1 / 3)
    assert "undetermined in 33.3 % of trials" in items_table([row] + [
        {"item": name, "clause": "", "unit": "", "truth": 0.0, "mean_error": 0.0, "std_error": 0.0, "mc_U95": 0.0}
        for _title, names in GROUPS for name in names if name != "threshold"])


def test_resolution_zero_noise_identity(ideal_document):
    """Eq. (14) on a unit reading its input in steps r = 0.01 °/s, base rate 0.5 °/s (50 steps: on a level). The
    output increment of ΔΩ is r·floor(ΔΩ/r + ½): 0.0063 °/s reads 0.01 (59 % off: fails), 0.01 reads 0.01 (0 %),
    0.016 reads 0.02 (25 %), 0.025 reads 0.03 (20 %), larger ones < 20 %. Going down the increments the last
    within 50 % is 0.01 °/s = r in each direction (the negative one likewise), the truth."""
    got, want, _kg = _noise_free(ideal_document, jjf1535_procedure(100 * DEG), gyro_resolution=0.01 * DEG)
    assert want["resolution"] == got["resolution"] == 0.01 * DEG
    # the staircase has a level at zero: |w| < r/2 reads 0, a dead zone of r/2 (eq. (13): 0.0063 reads 0.01, 59 %)
    assert got["threshold"] == 0.01 * DEG and want["threshold"] == 0.0


def test_warm_up_zero_noise_identity_and_by_hand(ideal_document):
    """7.2.9 on a transient of 100 °/h, τ = 120 s, from power-on, specified stability 10 °/h, P = 10 s: the
    reported warm-up time equals the truth, and the truth is the first period boundary t = 10·j s from which the
    standard deviation (n − 1) of the 10-s means of the transient (summed sample by sample here) is ≤ 10 °/h."""
    procedure = jjf1535_procedure(100 * DEG)
    A, tau = 100 * DEG_H, 120.0
    got, want, kg = _noise_free(ideal_document, procedure, gyro_warm_up_amplitude=A, gyro_warm_up_time_constant=tau)
    t = np.arange(len(procedure.warm_up[0]) * 10.0)
    means = (A * np.exp(-t / tau)).reshape(-1, 10).mean(axis=1) / kg
    by_hand = 10.0 * next(j for j in range(means.size - 9) if np.std(means[j:], ddof=1) <= 10 * DEG_H)
    assert want["warm_up_time"] == by_hand > 0
    assert got["warm_up_time"] == want["warm_up_time"]
    # a longer time constant takes longer; without a transient the warm-up time is 0
    assert _noise_free(ideal_document, procedure, gyro_warm_up_amplitude=A,
                       gyro_warm_up_time_constant=2 * tau)[1]["warm_up_time"] > by_hand
    assert _noise_free(ideal_document, procedure)[1]["warm_up_time"] == 0.0


def test_bias_repeatability_is_eq_20_of_the_turn_on_draws(ideal_document):
    """A turn-on bias of σ = 5 °/h per power cycle, no noise: eq. (20) is the standard deviation (Q − 1) of the Q
    room bias records' B0m = (Bg + b_q)/K, i.e. of the draws b_q of their power cycles (numpy's generator seeded
    (seed, trial, TURN_ON_STREAM)) divided by K; the truth is σ/K. The at-rest outputs before and after each rate
    run share its power cycle, so K, and eq. (10)'s repeatability (truth 0), do not see the turn-on bias."""
    procedure = jjf1535_procedure(100 * DEG)
    sigma = 5 * DEG_H
    got, want, kg = _noise_free(ideal_document, procedure, seed=11, trial=3, gyro_turn_on_bias=sigma)
    draws = np.random.default_rng((11, 3, TURN_ON_STREAM)).standard_normal(len(procedure.power_on))
    cycle = procedure.power_cycles()[0]
    records = [cycle[rec[0]] for rec in procedure.room_bias]
    assert len(set(records)) == len(records)  # each record in its own power cycle (7.2.11.1)
    assert got["bias_repeatability"] == pytest.approx(np.std(sigma * draws[records], ddof=1) / kg, rel=1e-9)
    assert want["bias_repeatability"] == sigma / kg
    assert got["scale_factor"] == pytest.approx(kg, rel=1e-12) and abs(got["scale_repeatability"]) < 1e-12


def test_effects_off_the_earlier_items_bit_for_bit():
    """No JJF 1535 effect set: the procedure's new segments come after all the others, so the earlier items'
    random draws, and their values, are those of commit f784c7a (:data:`BEFORE`).

    Equal to 1e-9 relative, not bit for bit: a fresh install's numpy/scipy/BLAS build may sum the least squares
    in another order (seen: the asymmetry differed by 6e-13 relative on a new machine), while another draw would
    move every item by the noise, ~1e-3 relative or more."""
    result = jjf1535_run("jjf2003", trials=2, seed=20151)
    for item, values in BEFORE.items():
        assert result.column(item).tolist() == pytest.approx(list(values), rel=1e-9, abs=1e-300), item


def test_the_monte_carlo_adds_the_effects_and_reports_them(ideal_document):
    """The ideal unit through the kernels (keep_table: no table error, no Earth rate, no noise) with all four
    effects: threshold, resolution and warm-up time come back exactly in both trials; the bias repeatability
    scatters from trial to trial around its truth σ/K, and the summary shows the reported figure's spread."""
    effects = {"gyro_dead_zone": 0.01 * DEG, "gyro_resolution": 0.01 * DEG, "gyro_warm_up_amplitude": 100 * DEG_H,
               "gyro_warm_up_time_constant": 120.0, "gyro_turn_on_bias": 5 * DEG_H}
    scenario = parse_scenario(ideal_document)
    scenario = dataclasses.replace(scenario, effects=dataclasses.replace(
        scenario.effects, **{name: _x(value) for name, value in effects.items()}))
    result = jjf1535_run(scenario, trials=2, seed=5, keep_table=True)
    for item in ("threshold", "resolution", "warm_up_time"):
        assert result.column(item).tolist() == result.column(item, "truth").tolist(), item
    assert result.column("threshold")[0] == 0.01 * DEG and result.column("warm_up_time")[0] > 0
    rep = result.column("bias_repeatability")
    assert rep[0] != rep[1] and np.all(result.column("bias_repeatability", "truth") == 5 * DEG_H / 1.0021)
    row = {r["item"]: r for r in result.summary()}["bias_repeatability"]
    assert {"truth", "mean_error", "mean", "std", "q025", "q975"} <= set(row) and row["undetermined"] == 0.0


def test_plansim_run_jjf1535_with_a_dead_zone_set(capsys):
    """As a user runs it: --set a dead zone on the ideal unit; the JSON's threshold item has truth 0.01 °/s in
    rad/s and the reported figure's distribution; the text names the effect in its header."""
    dead_zone = '--set=mimu.effects.gyro_dead_zone=["0.01 deg/s", "0 deg/s", "0 deg/s"]'
    code = cli.main(["run", "jjf1535", "--unit", "ideal", dead_zone, "--trials", "2", "--seed", "3", "--quiet",
                     "--json"])
    out = capsys.readouterr().out
    assert code == 0
    items = {i["item"]: i for i in json.loads(out)["items"]}
    assert items["threshold"]["truth"] == pytest.approx(0.01 * DEG, rel=1e-15)
    assert items["threshold"]["unit"] == "rad/s" and set(items["threshold"]["figure"]) == {"mean", "std", "q025",
                                                                                           "q975"}
    assert cli.main(["run", "jjf1535", "--unit", "ideal", dead_zone, "--trials", "2", "--quiet"]) == 0
    assert "dead zone 0.01 °/s" in capsys.readouterr().out


def test_bad_input(ideal_document):
    """Each error names the field, the value and what is allowed."""
    doc = json.loads(json.dumps(ideal_document))
    doc["mimu"].setdefault("effects", {})["gyro_dead_zone"] = ["-0.01 deg/s", "0 deg/s", "0 deg/s"]
    with pytest.raises(ValueError, match=r"mimu\.effects\.gyro_dead_zone = .*-0\.01 deg/s.*>= 0"):
        parse_scenario(doc)
    doc = json.loads(json.dumps(ideal_document))
    doc["mimu"].setdefault("effects", {})["gyro_warm_up_amplitude"] = ["100 deg/h", "0 deg/h", "0 deg/h"]
    with pytest.raises(ValueError, match=r"gyro_warm_up_time_constant = None: gyro x has a warm-up amplitude"):
        parse_scenario(doc)
    doc["mimu"]["effects"]["gyro_warm_up_time_constant"] = ["2 min", "0 s", "0 s"]
    scenario = parse_scenario(doc)
    assert scenario.effects.gyro_warm_up_time_constant[0] == 120.0
    # the JJF 2003 kernels do not simulate it: a JJF 2003 simulation refuses the scenario, naming the field
    with pytest.raises(ValueError, match=r"mimu\.effects\.gyro_warm_up_amplitude .*only the JJF 1535 Monte Carlo"):
        simulate_recording(scenario, seed=1, trial=0)
    with pytest.raises(ValueError, match=r"warm_up_duration = 95.0 s .* whole number \(>= 10\)"):
        jjf1535_procedure(100 * DEG, warm_up_duration=95.0)
    with pytest.raises(ValueError, match=r"warm_up_records = 0"):
        jjf1535_procedure(100 * DEG, warm_up_records=0)
    with pytest.raises(ValueError, match=r"dead_zone = -1"):
        input_response([0.1], -1.0, 0.0)
    with pytest.raises(ValueError, match=r"time_constant = 0.0"):
        exponential_segment_mean(0.0, 1, 1.0, 1.0, 0.0)
