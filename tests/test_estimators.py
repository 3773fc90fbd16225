"""The JJF 2003-2022 data reduction (plansim.estimate.jjf2003) against hand-worked examples.

Every small example below is worked out by hand in its comment, citing the equation of the
specification (JJF 2003-2022 §7.2.1–§7.2.5, eq. (3)–(13)), so a reader can check the expected
numbers without running code.
No simulator is run here: segment means are built analytically from a known truth.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plansim.config import parse_scenario
from plansim.estimate.jjf2003 import (
    DESIGN_MATRIX_A,
    check_design,
    line_fit,
    multi_position_design,
    multi_position_fit,
    rate_sensitivity,
    reduce,
    reduction_matrix,
    segment_mean,
)
from plansim.model.parameters import N_PARAMETERS, PARAMETER_NAMES, pack, unpack
from plansim.schedule import axis_vector, jjf2003
from plansim.units import DEG, STANDARD_GRAVITY

RATE_POINTS_DEG = [-100.0, -50.0, -20.0, -5.0, 0.0, 5.0, 20.0, 50.0, 100.0]  # as in scenarios/ideal.toml
RATE_POINTS = [r * DEG for r in RATE_POINTS_DEG]
OMEGA_SQUARED_RATE = 100.0 * DEG


# ----------------------------------------------------------------------------- eq. (3): segment mean


def test_segment_mean_is_eq3_average_over_the_last_axis():
    # eq. (3) U_k = (1/N) Σ U_ki: (1 + 2 + 6)/3 = 3 and (−1 + 0 + 4)/3 = 1
    samples = np.array([[1.0, 2.0, 6.0], [-1.0, 0.0, 4.0]])
    np.testing.assert_allclose(segment_mean(samples), [3.0, 1.0], rtol=0, atol=1e-15)


# ----------------------------------------------------------------------------- eq. (4)-(5): line fit


def test_line_fit_exact_line_five_points():
    # U = 3 X + 0.5 at X = −2, −1, 0, 1, 2  ->  U = −5.5, −2.5, 0.5, 3.5, 6.5
    # eq. (5): HᵀH = [[Σx², Σx], [Σx, n]] = [[10, 0], [0, 5]], HᵀU = [ΣxU, ΣU] = [30, 2.5]
    # -> K = 30/10 = 3, b = 2.5/5 = 0.5
    rates = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    outputs = np.array([-5.5, -2.5, 0.5, 3.5, 6.5])
    K, b = line_fit(rates, outputs)
    assert K == pytest.approx(3.0, rel=1e-14)
    assert b == pytest.approx(0.5, rel=1e-14)


def test_line_fit_noisy_three_points_by_hand():
    # X = −1, 0, 1; U = −2.9, 0.2, 3.0 (not on a line)
    # x̄ = 0, Σ(x − x̄)² = 2, Σ(x − x̄)U = 2.9 + 3.0 = 5.9 -> K = 5.9/2 = 2.95
    # b = Ū − K x̄ = (−2.9 + 0.2 + 3.0)/3 = 0.1
    K, b = line_fit(np.array([-1.0, 0.0, 1.0]), np.array([-2.9, 0.2, 3.0]))
    assert K == pytest.approx(2.95, rel=1e-14)
    assert b == pytest.approx(0.1, rel=1e-13)


def test_line_fit_noisy_four_points_by_hand_via_normal_equations():
    # X = 0, 1, 2, 3; U = 1.1, 2.9, 5.2, 6.8
    # eq. (5): HᵀH = [[Σx², Σx], [Σx, n]] = [[14, 6], [6, 4]], det = 56 − 36 = 20
    #          HᵀU = [ΣxU, ΣU] = [0 + 2.9 + 10.4 + 20.4, 16.0] = [33.7, 16.0]
    # K = (4·33.7 − 6·16)/20 = 38.8/20 = 1.94
    # b = (14·16 − 6·33.7)/20 = 21.8/20 = 1.09
    # (check: x̄ = 1.5, Σ(x−x̄)² = 5, Σ(x−x̄)U = 9.7 -> K = 1.94, b = 4.0 − 1.94·1.5 = 1.09)
    K, b = line_fit(np.array([0.0, 1.0, 2.0, 3.0]), np.array([1.1, 2.9, 5.2, 6.8]))
    assert K == pytest.approx(1.94, rel=1e-13)
    assert b == pytest.approx(1.09, rel=1e-13)


def test_line_fit_vectorises_over_leading_dimensions():
    # rows: the exact line 3X + 0.5 and the negated one −3X − 0.5 at X = −2 … 2
    rates = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])
    row = np.array([-5.5, -2.5, 0.5, 3.5, 6.5])
    outputs = np.stack([np.stack([row, -row]), np.stack([2 * row, 0 * row])])  # (2, 2, 5)
    K, b = line_fit(rates, outputs)
    assert K.shape == b.shape == (2, 2)
    np.testing.assert_allclose(K, [[3.0, -3.0], [6.0, 0.0]], rtol=1e-14, atol=1e-14)
    np.testing.assert_allclose(b, [[0.5, -0.5], [1.0, 0.0]], rtol=1e-14, atol=1e-14)


@pytest.mark.parametrize("rates", [[5.0], [5.0, 5.0, 5.0]])
def test_line_fit_needs_two_distinct_rates(rates):
    with pytest.raises(ValueError, match="at least 2 distinct rates"):
        line_fit(np.array(rates), np.ones(len(rates)))


@settings(max_examples=200, deadline=None)
@given(
    integer_rates=st.lists(st.integers(-50, 50), min_size=2, max_size=11, unique=True),
    scale=st.floats(1e-3, 1e3),
    K=st.floats(-1e3, 1e3),
    b=st.floats(-1e3, 1e3),
)
def test_line_fit_recovers_any_exact_line(integer_rates, scale, K, b):
    # rates: 2 to 11 distinct points (JJF 2003 asks for 7 to 11), spacing ≥ scale, so HᵀH is
    # well conditioned; the fit of exact data must return the line to rounding error
    rates = scale * np.array(integer_rates, dtype=float)
    outputs = K * rates + b
    K_hat, b_hat = line_fit(rates, outputs)
    span = np.max(np.abs(rates))
    size = abs(K) * span + abs(b)  # magnitude of the outputs
    assert abs(K_hat - K) <= 1e-11 * size / scale + 1e-300
    assert abs(b_hat - b) <= 1e-11 * size * (1 + span / scale) + 1e-300


# ----------------------------------------------------------------------------- eq. (6)-(11): multi-position


def test_design_matrix_is_eq6():
    expected = np.array([[1, -1, 0, 0, 0, 0],
                         [0, 0, 1, -1, 0, 0],
                         [0, 0, 0, 0, 1, -1],
                         [1, 1, 1, 1, 1, 1]], dtype=float)
    np.testing.assert_array_equal(DESIGN_MATRIX_A, expected)
    # A Aᵀ = diag(2, 2, 2, 6): the closed form used in the hand-worked examples below
    np.testing.assert_array_equal(DESIGN_MATRIX_A @ DESIGN_MATRIX_A.T, np.diag([2.0, 2.0, 2.0, 6.0]))


def test_multi_position_fit_single_row_reduces_to_appendix_a_formulas():
    # With A Aᵀ = diag(2, 2, 2, 6), eq. (7) Ḡ = U Aᵀ (A Aᵀ)⁻¹ becomes, row by row,
    #   g_x· = (U1 − U2)/2, g_y· = (U3 − U4)/2, g_z· = (U5 − U6)/2, B = (U1 + … + U6)/6,
    # which is Appendix A's simplification (A.2: B = mean of the 6 groups; A.3: gxx = (U1 − U2)/2).
    # U = [5, 1, 3.5, 2.5, 4, 2]:
    #   gxx = (5 − 1)/2 = 2, gxy = (3.5 − 2.5)/2 = 0.5, gxz = (4 − 2)/2 = 1, B = 18/6 = 3
    U = np.array([[5.0, 1.0, 3.5, 2.5, 4.0, 2.0]])
    fitted = multi_position_fit(U, DESIGN_MATRIX_A)
    assert fitted.shape == (1, 4)
    np.testing.assert_allclose(fitted[0], [2.0, 0.5, 1.0, 3.0], rtol=1e-14, atol=1e-14)


def test_multi_position_fit_least_squares_not_interpolation():
    # U = [1, 0, 0, 0, 0, 0] is not of the form [G|B]·A (6 data, 4 unknowns): least squares gives
    #   gxx = (1 − 0)/2 = 0.5, gxy = gxz = 0, B = 1/6
    # and the residual U − Ḡ A = [1 − 0.5 − 1/6, 0.5 − 1/6, −1/6, −1/6, −1/6, −1/6]
    #                          = [1/3, 1/3, −1/6, −1/6, −1/6, −1/6] sums to 0 and is ⟂ to each row of A
    U = np.array([[1.0, 0.0, 0.0, 0.0, 0.0, 0.0]])
    fitted = multi_position_fit(U, DESIGN_MATRIX_A)
    np.testing.assert_allclose(fitted[0], [0.5, 0.0, 0.0, 1.0 / 6.0], rtol=1e-14, atol=1e-15)
    residual = U - fitted @ DESIGN_MATRIX_A
    np.testing.assert_allclose(residual[0], [1 / 3, 1 / 3, -1 / 6, -1 / 6, -1 / 6, -1 / 6], atol=1e-15)
    np.testing.assert_allclose(residual @ DESIGN_MATRIX_A.T, 0.0, atol=1e-15)


def test_multi_position_fit_full_3x6_from_known_G_B():
    # Known [G | B] (eq. (8)), 3 sensors:
    G = np.array([[2.0, 0.5, -1.0],
                  [0.1, 3.0, 0.2],
                  [-0.3, 0.4, 1.5]])
    B = np.array([10.0, -20.0, 5.0])
    # eq. (6) Ug = [G|B]·A, column by column (group i: +x, −x, +y, −y, +z, −z up):
    #   U1 = B + G[:,0] = [12, −19.9, 4.7]     U2 = B − G[:,0] = [8, −20.1, 5.3]
    #   U3 = B + G[:,1] = [10.5, −17, 5.4]     U4 = B − G[:,1] = [9.5, −23, 4.6]
    #   U5 = B + G[:,2] = [9, −19.8, 6.5]      U6 = B − G[:,2] = [11, −20.2, 3.5]
    Ug = np.array([[12.0, 8.0, 10.5, 9.5, 9.0, 11.0],
                   [-19.9, -20.1, -17.0, -23.0, -19.8, -20.2],
                   [4.7, 5.3, 5.4, 4.6, 6.5, 3.5]])
    np.testing.assert_allclose(np.column_stack([G, B]) @ DESIGN_MATRIX_A, Ug, rtol=1e-15, atol=1e-14)
    fitted = multi_position_fit(Ug, DESIGN_MATRIX_A)  # eq. (7)
    np.testing.assert_allclose(fitted, np.column_stack([G, B]), rtol=1e-13, atol=1e-13)


def _design_12():
    # the 12-position test: each column of eq. (6) twice (two headings), in group order
    return np.repeat(DESIGN_MATRIX_A, 2, axis=1)


finite = st.floats(-1e3, 1e3, allow_nan=False, allow_infinity=False)


@settings(max_examples=200, deadline=None)
@given(values=st.lists(finite, min_size=12, max_size=12),
       design=st.sampled_from(["6", "12"]))
def test_multi_position_fit_recovers_any_G_B(values, design):
    GB = np.array(values).reshape(3, 4)
    A = DESIGN_MATRIX_A if design == "6" else _design_12()
    U = GB @ A
    fitted = multi_position_fit(U, A)
    scale = np.max(np.abs(GB)) + 1.0
    np.testing.assert_allclose(fitted, GB, rtol=0, atol=1e-12 * scale)


def test_multi_position_fit_vectorises_over_trials():
    rng = np.random.default_rng(20221)
    GB = rng.normal(size=(7, 3, 4))
    U = GB @ DESIGN_MATRIX_A
    np.testing.assert_allclose(multi_position_fit(U, DESIGN_MATRIX_A), GB, rtol=0, atol=1e-13)


# ----------------------------------------------------------------------------- eq. (12)-(13): ω² test


def test_rate_sensitivity_sign_conventions():
    # eq. (2) a'_Y = … + p_yx·ω_X²: U7 (at rest) = 0.02, p = 0.004, ω = 2 rad/s (ω² = 4)
    # -> U8 (rotating) = U7 + p·ω² = 0.02 + 0.016 = 0.036
    # "model":      (U8 − U7)/ω² = 0.016/4 = +0.004 = +p
    # "as_printed": (U7 − U8)/ω² (eq. (12) as printed) = −0.004 = −p  (§7.2.5.2 disagrees with eq. (2) of §5.2)
    p, omega, u7 = 0.004, 2.0, 0.02
    u8 = u7 + p * omega**2
    assert u8 == pytest.approx(0.036, rel=1e-15)
    assert rate_sensitivity(u7, u8, omega, sign="model") == pytest.approx(p, rel=1e-12)
    assert rate_sensitivity(u7, u8, omega) == pytest.approx(p, rel=1e-12)  # "model" is the default
    assert rate_sensitivity(u7, u8, omega, sign="as_printed") == pytest.approx(-p, rel=1e-12)


def test_rate_sensitivity_vectorised_per_channel():
    # three accelerometers at once: U7 = [9.8, 0.01, −0.02], p column = [0, 3e-4, −2e-4], ω = 1.5
    # U8 = U7 + p·2.25 = [9.8, 0.010675, −0.02045]
    u7 = np.array([9.8, 0.01, -0.02])
    p = np.array([0.0, 3e-4, -2e-4])
    u8 = np.array([9.8, 0.010675, -0.02045])
    np.testing.assert_allclose(rate_sensitivity(u7, u8, 1.5), p, rtol=0, atol=1e-15)


def test_rate_sensitivity_rejects_unknown_sign():
    with pytest.raises(ValueError, match="omega_squared_sign.*'model', 'as_printed'"):
        rate_sensitivity(0.0, 1.0, 1.0, sign="printed")


# ----------------------------------------------------------------------------- the whole reduction


def analytic_means(schedule, truth, gravity):
    """Noise-free segment means of eq. (1)-(2), from the nominal schedule and a truth vector.

    Each segment: specific force f = gravity·(up axis) (a resting accelerometer reads +1 g on the axis
    pointing up), body rate ω = rate·(rate axis); Earth rate and every other effect off.
    """
    m = unpack(truth)
    out = np.empty((len(schedule), 6))
    for k, s in enumerate(schedule.segments):
        f = gravity * axis_vector(s.up)
        w = s.rate * axis_vector(s.rate_axis)
        out[k, :3] = m["Kg"] @ w + m["Bg"] + m["G"] @ f  # eq. (1)
        out[k, 3:] = m["Ka"] @ f + m["Ba"] + m["P"] @ (w * w)  # eq. (2)
    return out


@pytest.fixture
def ideal_truth(ideal_document):
    return parse_scenario(ideal_document).truth_nominal


def random_truth(seed):
    """A plausible random truth; every parameter has magnitude in [0.5, 1] × its scale, random sign,
    so that none is near zero and a purely relative check is meaningful."""
    rng = np.random.default_rng(seed)

    def draw(scale, shape):
        return scale * rng.uniform(0.5, 1.0, shape) * rng.choice([-1.0, 1.0], shape)

    Kg = np.eye(3) + draw(1e-3, (3, 3))
    Ka = np.eye(3) + draw(1e-3, (3, 3))
    Bg = draw(3e-3, 3)  # rad/s (≈ 0.2 °/s)
    Ba = draw(0.05, 3)  # m/s² (≈ 5 mg)
    G = draw(1e-5, (3, 3))  # rad/s per m/s² (≈ 20 °/h/g)
    P = draw(5e-4, (3, 3))  # m/s² per (rad/s)² (≈ 50 µg/(rad/s)²)
    return pack(Kg, Bg, G, Ka, Ba, P)


@pytest.mark.parametrize("positions", [12, 6])
@pytest.mark.parametrize("rate_points", [RATE_POINTS, [-50 * DEG, 200 * DEG], [0.0, 10 * DEG, 30 * DEG, 300 * DEG]])
@pytest.mark.parametrize("truth_source", ["ideal", 1, 2])
def test_reduce_recovers_truth_from_analytic_means(positions, rate_points, truth_source, ideal_truth):
    truth = ideal_truth if truth_source == "ideal" else random_truth(truth_source)
    gravity = 9.80115  # any value, as long as the lab uses the same one in matrix A
    schedule = jjf2003(rate_points=rate_points, omega_squared_rate=OMEGA_SQUARED_RATE, positions=positions)
    check_design(schedule)
    means = analytic_means(schedule, truth, gravity)
    estimate = reduce(means, schedule, reference_gravity=gravity)
    assert estimate.shape == (N_PARAMETERS,)
    assert np.all(truth != 0)
    relative = np.abs(estimate - truth) / np.abs(truth)
    worst = int(np.argmax(relative))
    assert relative[worst] <= 1e-12, f"{PARAMETER_NAMES[worst]}: estimate {estimate[worst]!r}, truth {truth[worst]!r}"


def test_reduce_as_printed_sign_negates_only_P(ideal_truth):
    schedule = jjf2003(rate_points=RATE_POINTS, omega_squared_rate=OMEGA_SQUARED_RATE)
    means = analytic_means(schedule, ideal_truth, STANDARD_GRAVITY)
    model = reduce(means, schedule, STANDARD_GRAVITY, omega_squared_sign="model")
    printed = reduce(means, schedule, STANDARD_GRAVITY, omega_squared_sign="as_printed")
    is_p = np.array([name.startswith("p") for name in PARAMETER_NAMES])
    assert is_p.sum() == 6
    np.testing.assert_allclose(printed[is_p], -ideal_truth[is_p], rtol=1e-12)
    np.testing.assert_array_equal(printed[~is_p], model[~is_p])


def test_reduce_wrong_reference_gravity_scales_G_and_Ka(ideal_truth):
    # matrix A in units of the lab's "1 g": if the lab divides by g_ref instead of the true g,
    # G and Ka come out scaled by g/g_ref, everything else unchanged
    g_true, g_ref = 9.80115, STANDARD_GRAVITY
    schedule = jjf2003(rate_points=RATE_POINTS, omega_squared_rate=OMEGA_SQUARED_RATE)
    estimate = reduce(analytic_means(schedule, ideal_truth, g_true), schedule, g_ref)
    scaled = np.array([name[0] == "g" or name.startswith("Ka") for name in PARAMETER_NAMES])
    np.testing.assert_allclose(estimate[scaled], ideal_truth[scaled] * g_true / g_ref, rtol=1e-12)
    np.testing.assert_allclose(estimate[~scaled], ideal_truth[~scaled], rtol=1e-12)


def test_reduce_vectorises_over_trials(ideal_truth):
    schedule = jjf2003(rate_points=RATE_POINTS, omega_squared_rate=OMEGA_SQUARED_RATE)
    truths = np.stack([ideal_truth, random_truth(3), random_truth(4)])
    means = np.stack([analytic_means(schedule, t, STANDARD_GRAVITY) for t in truths]).reshape(3, 1, len(schedule), 6)
    estimate = reduce(means, schedule, STANDARD_GRAVITY)
    assert estimate.shape == (3, 1, N_PARAMETERS)
    np.testing.assert_allclose(estimate[:, 0], truths, rtol=1e-12)


def test_multi_position_design_of_12_positions_is_eq6():
    schedule = jjf2003(rate_points=RATE_POINTS, omega_squared_rate=OMEGA_SQUARED_RATE, positions=12)
    groups, members, design = multi_position_design(schedule)
    assert groups == [1, 2, 3, 4, 5, 6]
    assert [len(m) for m in members] == [2] * 6
    np.testing.assert_array_equal(design, DESIGN_MATRIX_A)


# ----------------------------------------------------------------------------- white noise: closed form


def _tolerance(count):
    """5 standard errors of a sample variance of *count* normal draws, relative: 5·√(2/(count−1))."""
    return 5.0 * math.sqrt(2.0 / (count - 1))


def test_line_fit_white_noise_variance_closed_form():
    # U_k = K X_k + b + ε_k with ε ~ N(0, σ²) i.i.d.: var(K̂) = σ²/Σ(x − x̄)²,
    # var(b̂) = σ²(1/n + x̄²/Σ(x − x̄)²), cov(K̂, b̂) = −σ² x̄/Σ(x − x̄)²
    rng = np.random.default_rng(2003)
    reps = 20000
    x = np.array([0.0, 1.0, 2.0, 5.0, 10.0])  # asymmetric, so b̂ and K̂ are correlated
    sigma, K, b = 0.3, 1.7, -0.4
    outputs = K * x + b + sigma * rng.standard_normal((reps, x.size))
    K_hat, b_hat = line_fit(x, outputs)
    sxx = np.sum((x - x.mean()) ** 2)
    var_K = sigma**2 / sxx
    var_b = sigma**2 * (1 / x.size + x.mean() ** 2 / sxx)
    tol = _tolerance(reps)
    assert np.var(K_hat, ddof=1) == pytest.approx(var_K, rel=tol)
    assert np.var(b_hat, ddof=1) == pytest.approx(var_b, rel=tol)
    # unbiased: the mean is within 5 standard errors of the truth
    assert abs(np.mean(K_hat) - K) <= 5 * math.sqrt(var_K / reps)
    assert abs(np.mean(b_hat) - b) <= 5 * math.sqrt(var_b / reps)
    # correlation coefficient: its standard error is about (1 − ρ²)/√reps
    rho = -x.mean() / math.sqrt(sxx) / math.sqrt(1 / x.size + x.mean() ** 2 / sxx)
    rho_hat = np.corrcoef(K_hat, b_hat)[0, 1]
    assert abs(rho_hat - rho) <= 5 * (1 - rho**2) / math.sqrt(reps)


def test_reduce_white_noise_on_rate_points_only_gives_closed_form_Kg_variance(ideal_truth):
    # Noise σ on every output of the rate-test segments only: each column of Kg (§7.2.3) is a slope
    # fitted to the 9 rate points, so var(Kg_ij) = σ²/Σ(x − x̄)²; every other estimate uses other
    # segments and must not move at all.
    rng = np.random.default_rng(7)
    reps = 20000
    schedule = jjf2003(rate_points=RATE_POINTS, omega_squared_rate=OMEGA_SQUARED_RATE)
    g = STANDARD_GRAVITY
    clean = analytic_means(schedule, ideal_truth, g)
    sigma = 1e-3  # rad/s (gyro) and m/s² (accelerometer outputs of the same segments)
    rate_rows = schedule.select("rate")
    assert len(rate_rows) == 3 * len(RATE_POINTS)
    means = np.broadcast_to(clean, (reps,) + clean.shape).copy()
    means[:, rate_rows, :] += sigma * rng.standard_normal((reps, len(rate_rows), 6))
    estimate = reduce(means, schedule, g)
    x = np.array(RATE_POINTS)
    var_K = sigma**2 / np.sum((x - x.mean()) ** 2)
    tol = _tolerance(reps)
    is_Kg = np.array([name.startswith("Kg") for name in PARAMETER_NAMES])
    for k in np.flatnonzero(is_Kg):
        assert np.var(estimate[:, k], ddof=1) == pytest.approx(var_K, rel=tol), PARAMETER_NAMES[k]
        assert abs(np.mean(estimate[:, k]) - ideal_truth[k]) <= 5 * math.sqrt(var_K / reps), PARAMETER_NAMES[k]
    noise_free = reduce(clean, schedule, g)
    np.testing.assert_allclose(estimate[:, ~is_Kg], np.broadcast_to(noise_free[~is_Kg], (reps, (~is_Kg).sum())),
                               rtol=1e-12, atol=0)


# ----------------------------------------------------------------------------- the reduction as one matrix


@pytest.mark.parametrize("positions, rate_points", [(12, RATE_POINTS), (6, [-3.0, 0.5, 2.0])])
@pytest.mark.parametrize("sign", ["model", "as_printed"])
def test_reduction_matrix_is_reduce_to_rounding(positions, rate_points, sign):
    """The estimators are linear in the segment means, so reduce is one matrix (runner.run uses it)."""
    schedule = jjf2003(rate_points=rate_points, omega_squared_rate=OMEGA_SQUARED_RATE, positions=positions)
    matrix = reduction_matrix(schedule, STANDARD_GRAVITY, sign)
    assert matrix.shape == (6 * len(schedule), N_PARAMETERS)
    means = np.random.default_rng(positions).normal(0.0, 5.0, size=(50, len(schedule), 6))
    direct = reduce(means, schedule, STANDARD_GRAVITY, sign)
    scale = np.abs(means.reshape(50, -1)) @ np.abs(matrix)  # what rounding can reach, per estimate
    assert np.all(np.abs(means.reshape(50, -1) @ matrix - direct) <= 1e-13 * scale)


def test_a_reduction_that_is_not_linear_is_not_made_a_matrix(monkeypatch):
    """If reduce were not linear, reduction_matrix refuses (None) and runner.run falls back to reduce."""
    import plansim
    import plansim.estimate.jjf2003 as module
    import plansim.runner as runner

    linear = module.reduce

    def squared(means, *args):
        estimate = linear(means, *args)
        return estimate + 1e-3 * estimate**2

    monkeypatch.setattr(module, "reduce", squared)
    schedule = jjf2003(rate_points=RATE_POINTS, omega_squared_rate=OMEGA_SQUARED_RATE)
    assert reduction_matrix(schedule, STANDARD_GRAVITY) is None
    monkeypatch.setattr(runner, "reduce", squared)
    monkeypatch.setattr(runner, "reduction_matrix", module.reduction_matrix)
    results = plansim.run("jjf2003", trials=3, seed=4, keep_segment_means=True)
    sc = plansim.load_scenario("jjf2003")
    expected = squared(results["segment_mean"].values, sc.schedule, sc.reduction.reference_gravity,
                       sc.reduction.omega_squared_sign)
    np.testing.assert_array_equal(results["estimate"].values, expected)
