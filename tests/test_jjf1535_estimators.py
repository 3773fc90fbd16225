"""JJF 1535-2015 clause 7.2 reductions, each on a hand-worked example, and Appendix A's arithmetic.

Every expected value below is worked by hand in the test's docstring or comment (not computed by the code
under test), so each assertion can fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.estimate import jjf1535 as e
from plansim.uncertainty.appendix_a_jjf1535 import BIAS, SCALE_FACTOR

RATES = np.array([-2.0, -1.0, 0.0, 1.0, 2.0])  # rad/s


def test_eq_4_5_line_fit_and_eq_6_nonlinearity():
    """F = 3Ω + 0.5 + v with v = (0, 0.1, −0.2, 0.1, 0): Σv = 0 and ΣΩv = −0.1 + 0.1 = 0, so the least-squares
    line is exactly K = 3, F0 = 0.5 and the residuals are v; eq. (6): max|v|/(K·(2 − (−2))) = 0.2/12."""
    v = np.array([0.0, 0.1, -0.2, 0.1, 0.0])
    samples = (3 * RATES + 0.5 + v)[:, None] + np.array([-0.01, 0.0, 0.01])  # eq. (4): the mean of 3 samples
    outputs = e.rate_point_mean(samples)
    fit = e.scale_factor_fit(RATES, outputs)
    assert fit.scale_factor == pytest.approx(3.0, abs=1e-12)
    assert fit.zero == pytest.approx(0.5, abs=1e-12)
    np.testing.assert_allclose(fit.residuals, v, atol=1e-12)
    assert e.scale_factor_nonlinearity(RATES, outputs) == pytest.approx(0.2 / 12, rel=1e-12)


def test_eq_8_asymmetry():
    """Slope 3.03 for Ω ≥ 0 and 2.97 for Ω ≤ 0 through the origin: K+ = 3.03, K− = 2.97, K̄ = 3,
    K_u = 0.06/3 = 0.02."""
    outputs = np.where(RATES >= 0, 3.03 * RATES, 2.97 * RATES)
    assert e.scale_factor_asymmetry(RATES, outputs) == pytest.approx(0.02, rel=1e-12)
    with pytest.raises(ValueError, match="two points on each side"):
        e.scale_factor_asymmetry([0.0, 1.0, 2.0], [0.0, 1.0, 2.0])


def test_eq_10_repeatability_and_eq_20():
    """K = (1.000, 1.002, 0.998): K̄ = 1, s = sqrt((0 + 4e-6 + 4e-6)/2) = 0.002, K_r = 0.002; the same numbers
    as biases give B_r = 0.002."""
    assert e.scale_factor_repeatability([1.000, 1.002, 0.998]) == pytest.approx(0.002, rel=1e-9)
    assert e.bias_repeatability([1.000, 1.002, 0.998]) == pytest.approx(0.002, rel=1e-9)


def test_eq_11_and_27_temperature_sensitivity():
    """K = 1, 1.004, 0.997 at 20, 60, −20 °C: |0.004/(1·40)| = 1e-4 and |−0.003/(1·−40)| = 7.5e-5, max 1e-4 /°C.
    Biases 0.01, 0.014, 0.007 rad/s: |0.004/40| = 1e-4, |−0.003/−40| = 7.5e-5: 1e-4 rad/s/°C."""
    T = [20.0, 60.0, -20.0]
    assert e.temperature_sensitivity([1.0, 1.004, 0.997], T) == pytest.approx(1e-4, rel=1e-9)
    assert e.temperature_sensitivity([0.01, 0.014, 0.007], T, relative=False) == pytest.approx(1e-4, rel=1e-9)
    with pytest.raises(ValueError, match="differ from room temperature"):
        e.temperature_sensitivity([1.0, 1.1], [20.0, 20.0])


def test_eq_12_13_threshold_and_eq_14_resolution():
    """K = 2, rates 0.1, 0.05, 0.02, 0.01, 0.005 rad/s; output less the zero-rate output 0.2, 0.1, 0.035, 0.012,
    0.002 against K·Ω = 0.2, 0.1, 0.04, 0.02, 0.01: relative deviations 0, 0, 12.5 %, 40 %, 80 %. The last
    within 50 % going down is 0.01 rad/s: the threshold. The same numbers as increments give the resolution."""
    rates = [0.1, 0.05, 0.02, 0.01, 0.005]
    measured = np.array([0.2, 0.1, 0.035, 0.012, 0.002])
    zero = 0.003
    assert e.threshold(2.0, rates, measured + zero, zero) == pytest.approx(0.01)
    assert e.threshold(2.0, [-r for r in rates], -measured + zero, zero) == pytest.approx(0.01)  # reverse
    assert e.resolution(2.0, rates, measured) == pytest.approx(0.01)
    assert math.isnan(e.threshold(2.0, [0.1], [0.5], 0.0))  # even the largest rate fails: no threshold found


def test_eq_15_to_19_bias_and_stability():
    """K = 2: at-rest mean 0.02 gives B0 = 0.01 rad/s. Outputs 0, 0, 2, 2, 4, 4 with P = 2: period means 0, 2,
    4, their s = 2, B_s = 2/K = 1 rad/s."""
    assert e.bias(2.0, [0.01, 0.03]) == pytest.approx(0.01)
    assert e.bias_stability(2.0, [0, 0, 2, 2, 4, 4], 2) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="at least two periods"):
        e.bias_stability(2.0, [0, 0, 2], 2)


def test_7_2_12_g_sensitivity_and_7_2_9_warm_up():
    """Up mean 0.5, down mean 0.3, g = 10, K = 2: (0.2/20)/2 = 0.005 rad/s per m/s². A bias of 1 rad/s for the
    first 100 s and 0 after (1 Hz, P = 10 s): the stability from t = 100 s on is 0, so the warm-up time is 100 s."""
    assert e.bias_g_sensitivity(2.0, [0.5, 0.5], [0.3, 0.3], 10.0) == pytest.approx(0.005)
    t = np.arange(1000.0)
    w = np.where(t < 100, 1.0, 0.0)
    assert e.warm_up_time(t, w, 1e-6, 10) == pytest.approx(100.0)
    assert math.isnan(e.warm_up_time(t, np.sin(t), 1e-6, 10))


def test_eq_25_26_allan_polynomial_recovers_its_terms_and_the_arw():
    """σ²(τ) = 4e-2/τ + 1e-3 + 2e-4·τ (no quantisation or ramp) at τ = 1 … 1024 s: the five-term least squares
    returns the three and zeros, and ARW = sqrt(4e-2) = 0.2."""
    tau = 2.0 ** np.arange(11)
    fit = e.allan_polynomial_fit(tau, 4e-2 / tau + 1e-3 + 2e-4 * tau)
    assert fit.angle_random_walk == pytest.approx(0.2, rel=1e-9)
    assert fit.coefficients[0] == pytest.approx(1e-3, rel=1e-7)
    assert fit.coefficients[1] == pytest.approx(2e-4, rel=1e-7)
    assert abs(fit.coefficients[-2]) < 1e-12 and abs(fit.coefficients[2]) < 1e-12


def test_allan_polynomial_on_white_noise_gives_its_arw():
    """White noise of density N = 0.01 rad/s/√Hz at 100 Hz (σ = N·√100 = 0.1 rad/s per sample), one hour: the
    Allan variance from allantools is N²/τ, and the fit's ARW is N within the scatter of the Allan estimates at
    the long τ (10 % here; seed fixed)."""
    import allantools

    rate = 100.0
    x = np.random.default_rng(3).normal(0.0, 0.01 * math.sqrt(rate), 360_000)
    taus, adev, _, _ = allantools.oadev(x, rate=rate, data_type="freq", taus="octave")
    fit = e.allan_polynomial_fit(taus, adev**2)
    assert fit.angle_random_walk == pytest.approx(0.01, rel=0.1)


def test_appendix_a_arithmetic_as_printed():
    """A.1.3: sqrt(2.5e-4² + 3.0e-5² + 4.65e-4²) = 5.2878e-4 → 5.29e-4, U_rel = 1.06e-3 → 1.1e-3; A.2.3:
    sqrt(3.0e-5² + 5.29e-4²) = 5.2985e-4 → 5.30e-4, U = 1.1e-3."""
    assert SCALE_FACTOR.combined_standard_uncertainty == pytest.approx(5.2878e-4, rel=1e-4)
    assert round(SCALE_FACTOR.combined_standard_uncertainty, 6) == SCALE_FACTOR.printed_combined_standard_uncertainty
    assert round(SCALE_FACTOR.expanded_uncertainty, 4) == SCALE_FACTOR.printed_expanded_uncertainty
    assert BIAS.combined_standard_uncertainty == pytest.approx(5.2985e-4, rel=1e-4)
    assert round(BIAS.combined_standard_uncertainty, 6) == BIAS.printed_combined_standard_uncertainty
    assert round(BIAS.expanded_uncertainty, 4) == BIAS.printed_expanded_uncertainty


def test_bad_input_names_the_field():
    with pytest.raises(ValueError, match="rates and outputs: expected the same length"):
        e.scale_factor_fit([1.0, 2.0, 3.0], [1.0, 2.0])
    with pytest.raises(ValueError, match="outputs: every value must be finite"):
        e.scale_factor_fit([1.0, 2.0], [1.0, float("nan")])
    with pytest.raises(TypeError, match="rates: expected numbers"):
        e.scale_factor_fit(["a", "b"], [1.0, 2.0])
    with pytest.raises(ValueError, match="gravity"):
        e.bias_g_sensitivity(1.0, [1.0], [0.0], 0.0)
