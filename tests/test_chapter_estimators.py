"""The textbook chapter's procedures (plansim.estimate.chapter, plansim.schedule.chapter).

Each estimator reproduces a hand-worked example (worked out in the comment beside it), and, where the
quantity has a true value in the model, the zero-noise identity: the simulator's own noise-free segment
means (:func:`plansim.simulate.arguments.noise_free_segment_means`, Earth rate on) reduce to the truth
to rounding.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from plansim.config import parse_scenario
from plansim.estimate import check_design
from plansim.estimate.chapter import (
    CHAPTER_EARTH_RATE,
    RANDOM_DRIFT_FACTOR,
    cross_axis_ratios,
    drift_model,
    drift_model_fit,
    earth_rate_inputs,
    eight_position_fit,
    random_drift,
    rate_misalignment,
    rate_misalignments,
    up_down,
)
from plansim.kernels.layout import TILT_FIRST, TRUTH
from plansim.model.environment import EARTH_RATE
from plansim.model.parameters import unpack
from plansim.schedule import Schedule
from plansim.schedule.chapter import (
    CHAPTER_TURN_RATE,
    FULL_TURN,
    drift_positions,
    eight_positions,
    rate_turns,
)
from plansim.simulate.arguments import noise_free_segment_means, nominal_draws
from plansim.units import DEG, HOUR

# ----------------------------------------------------------------------------- helpers


def random_truth(seed):
    """A plausible truth vector with every entry away from zero (as tests/test_estimators.py draws it)."""
    from plansim.model.parameters import pack

    rng = np.random.default_rng(seed)

    def draw(scale, shape):
        return scale * rng.uniform(0.5, 1.0, shape) * rng.choice([-1.0, 1.0], shape)

    return pack(np.eye(3) + draw(1e-3, (3, 3)), draw(3e-3, 3), draw(1e-5, (3, 3)), np.eye(3) + draw(1e-3, (3, 3)),
                draw(0.05, 3), draw(5e-4, (3, 3)))


def chapter_scenario(document, extra, earth_rate=True):
    """The ideal scenario (every error and noise off) with *extra* segments appended to its JJF 2003 schedule."""
    document["environment"]["earth_rate"] = earth_rate
    scenario = parse_scenario(document)
    schedule = Schedule(scenario.schedule.segments + tuple(extra))
    check_design(schedule)
    return dataclasses.replace(scenario, schedule=schedule)


def noise_free(scenario, truth=None, tilt=(0.0, 0.0)):
    draws = nominal_draws(scenario)
    if truth is not None:
        draws[TRUTH] = truth
    draws[TILT_FIRST:TILT_FIRST + 2] = tilt
    return noise_free_segment_means(scenario, draws[None])[0], unpack(draws[TRUTH])


# ----------------------------------------------------------------------------- the Earth rate


def test_chapter_earth_rate_is_the_sidereal_rate_not_the_printed_day():
    # 360° over one sidereal day, 23 h 56 min 4.09 s = 86164.09 s: 360·3600/86164.09 = 15.0410687 °/h,
    # which rounds to the chapter's 15.04107 °/h; the chapter's printed day, 23 h 59 min 57.33 s = 86397.33 s,
    # gives 360·3600/86397.33 = 15.00046 °/h, not the rate it states
    assert CHAPTER_EARTH_RATE == pytest.approx(15.04107 * math.pi / 180 / 3600, rel=1e-15)
    sidereal = 360.0 * 3600.0 / (23 * 3600 + 56 * 60 + 4.09)
    printed = 360.0 * 3600.0 / (23 * 3600 + 59 * 60 + 57.33)
    assert CHAPTER_EARTH_RATE / (DEG / HOUR) == pytest.approx(sidereal, abs=5e-6)
    assert abs(CHAPTER_EARTH_RATE / (DEG / HOUR) - printed) > 0.04
    assert CHAPTER_EARTH_RATE == pytest.approx(EARTH_RATE, rel=3e-7)


def test_earth_rate_inputs_of_hand_poses():
    # latitude 30°: Ω_enu = Ω·(0, cos 30°, sin 30°) = Ω·(0, 0.8660, 0.5). "+x" up, heading 0: x → Up, y → East,
    # z → North, so ω_body = Ω·(0.5, 0, 0.8660); "-z" up, heading 0: z → −Up, x → East, y → −North:
    # ω_body = Ω·(0, −0.8660, −0.5); "+x" up at heading 90°: y → North, z → −East: ω_body = Ω·(0.5, 0.8660, 0)
    segments = [eight_positions("x", headings=(0.0, math.pi / 2))[k] for k in (0, 1)] + eight_positions(
        "z", headings=(0.0,))[1:]
    omega = earth_rate_inputs(segments, math.radians(30.0), earth_rate=1.0)
    c = math.sqrt(3) / 2
    np.testing.assert_allclose(omega, [[0.5, 0.0, c], [0.5, c, 0.0], [0.0, -c, -0.5]], atol=1e-15)


# ----------------------------------------------------------------------------- eq. (6-8)


def test_rate_misalignment_hand_example_one_turn():
    # Y gyro with Kg_yx = 0.002, Kg_yy = 1.25, bias 0.01 rad/s; one turn about X at ±10 °/s takes 36 s:
    # E_y1 = 0.002·2π + 0.01·36 = 0.3725664, E_y2 = −0.002·2π + 0.01·36 = 0.3474336 (rad);
    # E_y1 − E_y2 = 2·0.002·2π = 0.008π (the bias cancels);
    # eq. (6-8): (E_y1 − E_y2)/(2·M·E_1y) = 0.008π/(2·2π·1.25) = 0.008π/(5π) = 0.0016 = 0.002/1.25
    e1 = 0.002 * 2 * math.pi + 0.01 * 36
    e2 = -0.002 * 2 * math.pi + 0.01 * 36
    assert rate_misalignment(e1, e2, 1.25) == pytest.approx(0.0016, rel=1e-12)


def test_rate_misalignment_hand_example_in_counts_and_two_turns():
    # a gyro reading counts: E1 = 500, E2 = 300 counts·s, E_1 = 2000 counts per rad/s, two turns (M = 4π):
    # (500 − 300)/(2·4π·2000) = 200/(16000π) = 1/(80π) = 0.00397887
    assert rate_misalignment(500.0, 300.0, 2000.0, angle=2 * FULL_TURN) == pytest.approx(1 / (80 * math.pi),
                                                                                         rel=1e-14)


def test_rate_misalignment_broadcasts_and_refuses_bad_input():
    out = rate_misalignment(np.array([1.0, 2.0]), np.array([0.0, 0.0]), np.array([1.0, 2.0]))
    np.testing.assert_allclose(out, [1 / (4 * math.pi), 2 / (8 * math.pi)], rtol=1e-15)
    with pytest.raises(ValueError, match="angle = 0.0 rad"):
        rate_misalignment(1.0, 0.0, 1.0, angle=0.0)
    with pytest.raises(ValueError, match="scale_factor"):
        rate_misalignment(1.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="output_plus: every value must be finite"):
        rate_misalignment(math.nan, 0.0, 1.0)


@pytest.mark.parametrize("truth_seed", [None, 3])
@pytest.mark.parametrize(("rate_deg", "turns"), [(10.0, 1), (20.0, 3)])
def test_rate_misalignments_zero_noise_identity(ideal_document, truth_seed, rate_deg, turns):
    """Noise-free means, Earth rate on: E_ab = Kg[b, a]/Kg[b, b] to rounding (the vertical Earth rate cancels
    between the + and − turns, the horizontal one over whole turns)."""
    scenario = chapter_scenario(ideal_document, rate_turns(rate_deg * DEG, turns))
    means, truth = noise_free(scenario, None if truth_seed is None else random_truth(truth_seed))
    estimate = rate_misalignments(means, scenario.schedule, np.diag(truth["Kg"]))
    expected = cross_axis_ratios(truth["Kg"])
    assert np.all(np.abs(expected[~np.eye(3, dtype=bool)]) > 1e-5)
    np.testing.assert_allclose(estimate, expected, rtol=0, atol=1e-12)


def test_rate_misalignments_vectorise_and_leave_axes_not_turned_nan(ideal_document):
    scenario = chapter_scenario(ideal_document, rate_turns(axes="y"))
    means, truth = noise_free(scenario)
    stacked = np.stack([means, means])
    estimate = rate_misalignments(stacked, scenario.schedule, np.diag(truth["Kg"]))
    assert estimate.shape == (2, 3, 3)
    assert np.all(np.isnan(estimate[:, :, [0, 2]]))
    np.testing.assert_allclose(estimate[:, :, 1], np.broadcast_to(cross_axis_ratios(truth["Kg"])[:, 1], (2, 3)),
                               atol=1e-12)


def test_rate_misalignments_refuse_bad_schedules():
    turns = rate_turns(axes="x")
    means = np.zeros((2, 6))
    with pytest.raises(ValueError, match="no 'rotation' segment"):
        rate_misalignments(np.zeros((1, 6)), eight_positions("x")[:1], np.ones(3))
    with pytest.raises(ValueError, match=r"1 \+ and 0 − runs"):
        rate_misalignments(np.zeros((1, 6)), turns[:1], np.ones(3))
    with pytest.raises(ValueError, match=r"means: expected shape \(\.\.\., 2, 6\)"):
        rate_misalignments(np.zeros((3, 6)), turns, np.ones(3))
    with pytest.raises(ValueError, match=r"scale_factors: expected shape \(\.\.\., 3\)"):
        rate_misalignments(means, turns, np.ones(2))
    with pytest.raises(TypeError, match="segments"):
        rate_misalignments(means, ["not a segment"], np.ones(3))


# ----------------------------------------------------------------------------- eq. (6-9), the 8-position test


def test_up_down_hand_example():
    # eq. (6-9) A = K0 + K1·a: up reads 9.9, down −9.7 with g = 9.8:
    # K0 = (9.9 − 9.7)/2 = 0.1, K1 = (9.9 + 9.7)/(2·9.8) = 19.6/19.6 = 1
    K0, K1 = up_down(9.9, -9.7, 9.8)
    assert K0 == pytest.approx(0.1, rel=1e-12)
    assert K1 == pytest.approx(1.0, rel=1e-15)
    with pytest.raises(ValueError, match="gravity = -1"):
        up_down(1.0, 1.0, -1.0)


def test_eight_position_fit_hand_example():
    # 8 positions about x, g = 10: accelerometers read (Ba + Ka[:, x]·(±10)) with Ba = (0.1, 0.2, 0.3) and
    # Ka[:, x] = (1.01, 0.002, −0.003), plus a heading-dependent ±0.05 on y that the four headings cancel:
    # up: (10.2, 0.22 + h, 0.27), down: (−10.0, 0.18 + h, 0.33) -> Ka[:, x] = ((10.2 + 10)/20, 0.04/20, −0.06/20)
    # = (1.01, 0.002, −0.003), Ba = ((10.2 − 10)/2, 0.2, 0.3)
    segments = eight_positions("x")
    h = np.array([0.05, -0.05, -0.05, 0.05])  # sums to 0 over the four headings
    means = np.zeros((8, 6))
    means[:4, 3:] = np.column_stack([np.full(4, 10.2), 0.22 + h, np.full(4, 0.27)])
    means[4:, 3:] = np.column_stack([np.full(4, -10.0), 0.18 + h, np.full(4, 0.33)])
    Ka, Ba = eight_position_fit(means, segments, 10.0)
    np.testing.assert_allclose(Ka[:, 0], [1.01, 0.002, -0.003], rtol=1e-12)
    assert np.all(np.isnan(Ka[:, 1:]))
    np.testing.assert_allclose(Ba, [0.1, 0.2, 0.3], rtol=1e-12)


@pytest.mark.parametrize("truth_seed", [None, 5])
def test_eight_position_fit_zero_noise_identity(ideal_document, truth_seed):
    scenario = chapter_scenario(ideal_document, eight_positions())
    means, truth = noise_free(scenario, None if truth_seed is None else random_truth(truth_seed))
    Ka, Ba = eight_position_fit(means, scenario.schedule, scenario.environment.gravity)
    g = scenario.environment.gravity  # outputs are ~g: rounding is 1e-12 of g, not of Ba
    np.testing.assert_allclose(Ka, truth["Ka"], rtol=0, atol=1e-12)
    np.testing.assert_allclose(Ba, truth["Ba"], rtol=0, atol=1e-12 * g)


def test_eight_positions_cancel_a_table_tilt_that_one_heading_does_not(ideal_document):
    """A 10″ platform tilt puts g·δ ≈ 4.8e-5 g on a horizontal accelerometer: one heading takes it for a
    cross-axis term, the four headings average it out (only δ²/2 ≈ 1e-9 is left)."""
    scenario = chapter_scenario(ideal_document, eight_positions())
    tilt = 10 * DEG / 3600
    means, truth = noise_free(scenario, tilt=(tilt, 0.5 * tilt))
    g = scenario.environment.gravity
    off = ~np.eye(3, dtype=bool)
    Ka, _ = eight_position_fit(means, scenario.schedule, g)
    assert np.max(np.abs(Ka - truth["Ka"])[off]) < 1e-10
    assert np.max(np.abs(np.diag(Ka - truth["Ka"]))) < tilt**2
    one_heading = [k for k, s in enumerate(scenario.schedule.segments) if s.test == "static" and s.heading == 0.0]
    Ka1, _ = eight_position_fit(means, scenario.schedule, g, indices=one_heading)
    assert np.max(np.abs(Ka1 - truth["Ka"])[off]) > 0.4 * tilt


def test_eight_position_fit_refuses():
    with pytest.raises(ValueError, match="needs an axis both up and down"):
        eight_position_fit(np.zeros((4, 6)), eight_positions("x")[:4], 9.8)
    turns = rate_turns(axes="x")
    with pytest.raises(ValueError, match="a position test uses segments at rest"):
        eight_position_fit(np.zeros((2, 6)), turns, 9.8, indices=[0])


# ----------------------------------------------------------------------------- the drift model, eq. (6-6)


def test_cross_axis_ratios_hand_example():
    # K = [[2, 0.4, −0.2], [0.1, 0.5, 0.05], [0, 3, 4]] -> rows over their diagonal:
    # [[0, 0.2, −0.1], [0.2, 0, 0.1], [0, 0.75, 0]]
    K = np.array([[2.0, 0.4, -0.2], [0.1, 0.5, 0.05], [0.0, 3.0, 4.0]])
    np.testing.assert_allclose(cross_axis_ratios(K), [[0, 0.2, -0.1], [0.2, 0, 0.1], [0, 0.75, 0]], atol=1e-16)
    with pytest.raises(ValueError, match="scale factor"):
        cross_axis_ratios(np.zeros((3, 3)))


def test_drift_model_fit_hand_example():
    # D = D0 + D1 a_X + D2 a_Y + D3 a_Z with D0 = 1, D1 = 2, D2 = 3, D3 = 4, six positions a = ±1 on each axis:
    # drifts 1 ± 2, 1 ± 3, 1 ± 4 = 3, −1, 4, −2, 5, −3. Least squares on this orthogonal design:
    # D0 = mean = (3 − 1 + 4 − 2 + 5 − 3)/6 = 1, D1 = (3 − (−1))/2 = 2, D2 = (4 + 2)/2 = 3, D3 = (5 + 3)/2 = 4
    force = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    drifts = np.array([[3.0, -1.0, 4.0, -2.0, 5.0, -3.0]] * 3)
    np.testing.assert_allclose(drift_model_fit(drifts, force), [[1.0, 2.0, 3.0, 4.0]] * 3, rtol=1e-14)
    # one noisy position: the drift at +x is 3.6 instead of 3 (0.6 more). Only D0 and D1 see that position:
    # D0 = (6 + 0.6)/6 = 1.1, D1 = (3.6 + 1)/2 = 2.3
    drifts[:, 0] = 3.6
    np.testing.assert_allclose(drift_model_fit(drifts, force)[0], [1.1, 2.3, 3.0, 4.0], rtol=1e-14)
    with pytest.raises(ValueError, match="rank-3 design"):
        drift_model_fit(drifts[:, :4], force[:4])


@pytest.mark.parametrize("truth_seed", [None, 7])
def test_drift_model_zero_noise_identity(ideal_document, truth_seed):
    """Earth rate on, removed with plansim's own Earth rate and the true Kg: D0 = Bg, D1..D3 = G to rounding.
    With the chapter's 15.04107 °/h and the scale factors only, what is left is Kg's cross-couplings times the
    Earth rate (≤ 1e-3·Ω) and Kg times the two rates' difference (≈ 2.4e-7·Ω)."""
    scenario = chapter_scenario(ideal_document, drift_positions())
    means, truth = noise_free(scenario, None if truth_seed is None else random_truth(truth_seed))
    g, latitude = scenario.environment.gravity, scenario.environment.latitude
    D = drift_model(means, scenario.schedule, g, latitude, truth["Kg"], earth_rate=EARTH_RATE)
    np.testing.assert_allclose(D[:, 0], truth["Bg"], rtol=0, atol=1e-15)
    np.testing.assert_allclose(D[:, 1:], truth["G"], rtol=0, atol=1e-15)
    rough = drift_model(means, scenario.schedule, g, latitude, np.diag(truth["Kg"]))
    off = np.abs(truth["Kg"] - np.diag(np.diag(truth["Kg"]))).sum(axis=1).max()
    # the six up-axes at headings 0 and π are symmetric: the leftover Earth rate cancels in D0 (to rounding),
    # and its vertical part, which flips sign with the up-axis as the force does, lands in D1..D3 (per g)
    assert np.max(np.abs(rough[:, 0] - truth["Bg"])) <= (off + 1e-6) * EARTH_RATE
    leftover = np.abs(rough[:, 1:] - truth["G"])
    assert np.max(leftover) <= (off + 1e-6) * EARTH_RATE / g
    assert np.max(leftover) > 1e-3 * 2.4e-7 * EARTH_RATE / g  # not rounding: at least the two rates' difference


def test_random_drift_hand_example():
    # drifts 1, 2, 3, 4: mean 2.5, Σ(d − d̄)² = 2.25 + 0.25 + 0.25 + 2.25 = 5, σ = √(5/3) = 1.2909944;
    # eq. (6-6): 2.7σ = 3.4856848
    assert RANDOM_DRIFT_FACTOR == 2.7
    assert random_drift([1.0, 2.0, 3.0, 4.0]) == pytest.approx(2.7 * math.sqrt(5 / 3), rel=1e-14)
    np.testing.assert_allclose(random_drift(np.array([[1.0, 5.0], [2.0, 5.0], [3.0, 5.0]])), [2.7, 0.0], rtol=1e-14)
    with pytest.raises(ValueError, match="a standard deviation needs >= 2"):
        random_drift([1.0])
    with pytest.raises(ValueError, match="axis = 2"):
        random_drift([1.0, 2.0], axis=2)


# ----------------------------------------------------------------------------- the builders


def test_rate_turns_cover_whole_turns():
    turns = rate_turns()
    assert [s.label for s in turns][:2] == ["turn x +10 deg/s x1", "turn x -10 deg/s x1"]
    assert len(turns) == 6
    for s in turns:
        assert s.test == "rotation" and s.up == s.rate_axis == f"+{'xyz'[s.group]}"
        assert s.samples == 3600 and abs(s.rate) == pytest.approx(CHAPTER_TURN_RATE)
        assert s.samples / s.sample_rate * abs(s.rate) == pytest.approx(FULL_TURN, rel=1e-14)
        assert s.angle == pytest.approx(math.copysign(FULL_TURN, s.rate), rel=1e-15)
    assert [s.samples for s in rate_turns(27 * DEG, 3)] == [4000] * 6


@pytest.mark.parametrize(("kwargs", "error", "match"), [
    ({"rate": 0.0}, ValueError, "rate = 0.0"),
    ({"rate": "10"}, TypeError, "rate = '10'"),
    ({"turns": 0}, ValueError, "turns = 0"),
    ({"turns": 1.5}, ValueError, "turns = 1.5"),
    ({"axes": "xw"}, ValueError, "axes = 'xw'"),
    ({"axes": "xx"}, ValueError, "axes = 'xx'"),
    ({"rate": 27 * DEG, "turns": 2}, ValueError, "2666.67 samples per run"),
])
def test_rate_turns_refuse(kwargs, error, match):
    with pytest.raises(error, match=match):
        rate_turns(**kwargs)


def test_eight_and_drift_positions():
    eight = eight_positions()
    assert len(eight) == 24 and all(s.test == "static" for s in eight)
    assert [s.up for s in eight[:8]] == ["+x"] * 4 + ["-x"] * 4
    assert [round(math.degrees(s.heading)) for s in eight[:8]] == [0, 90, 180, 270] * 2
    drift = drift_positions(repeats=2)
    assert len(drift) == 24 and {s.group for s in drift} == {0, 1}
    with pytest.raises(ValueError, match="repeats = 0"):
        drift_positions(repeats=0)
    with pytest.raises(ValueError, match="headings = \\(\\)"):
        eight_positions(headings=())
