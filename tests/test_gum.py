"""GUM budgets from the schedule (plansim.uncertainty.gum): the arithmetic against GTC, the derived
covariances against simulation, the systematic effects against closed forms, and the Appendix A slips.

Statistical tolerances are derived from the trial counts: the standard deviation of a sample
standard deviation s of n values is ≈ σ·sqrt((β₂ − 1)/(4n)) (β₂ the kurtosis, 3 for a normal), that
of a sample covariance c_st is sqrt((c_ss c_tt + c_st²)/n); tests allow Z = 5 of them.
"""

from __future__ import annotations

import dataclasses
import math

import GTC
import numpy as np
import pytest
from GTC import reporting, tb, ureal

from plansim.estimate import reduce
from plansim.io.scenario_file import load_scenario
from plansim.kernels.quantiser import quantised_gaussian_moments
from plansim.model.parameters import PARAMETER_INDEX, PARAMETER_NAMES, PARAMETERS, unpack
from plansim.report.validation import format_report
from plansim.runner import run, validate
from plansim.uncertainty import APPENDIX_A, appendix_a_budget
from plansim.uncertainty.drift import drift_covariance
from plansim.uncertainty.gum import evaluate_gum
from plansim.uncertainty.metrology import combine, coverage_factor, welch_satterthwaite
from plansim.uncertainty.quantisation import quantisation_covariance, quantisation_variance
from plansim.uncertainty.sensitivities import estimator_matrix
from plansim.uncertainty.systematic import systematic_effects

Z = 5.0  # standard errors allowed in the statistical comparisons
SEED = 20240603


@pytest.fixture(scope="module")
def jjf():
    return load_scenario("jjf2003")


@pytest.fixture(scope="module")
def linear():
    return load_scenario("linear_gaussian")


@pytest.fixture(scope="module")
def jjf_gum(jjf):
    return evaluate_gum(jjf)


@pytest.fixture(scope="module")
def linear_gum(linear):
    return evaluate_gum(linear)


def white_noise_only(scenario):
    """The scenario with every input but the white noise switched off (table, spread, drift, quantiser)."""
    t = scenario.turntable
    zero = dataclasses.replace(t.position_accuracy, scale=0.0)
    table = dataclasses.replace(t, **{f.name: zero for f in dataclasses.fields(t) if f.name != "rate_smoothness"},
                                rate_smoothness=0.0)
    n = scenario.noise
    noise = dataclasses.replace(n, gyro_bias_instability=np.zeros(3), accel_bias_instability=np.zeros(3),
                                gyro_rate_random_walk=np.zeros(3), accel_acceleration_random_walk=np.zeros(3),
                                gyro_markov_sigma=np.zeros(3), accel_markov_sigma=np.zeros(3))
    return dataclasses.replace(scenario, turntable=table, noise=noise,
                               truth_spread=np.zeros_like(scenario.truth_spread),
                               acquisition=dataclasses.replace(scenario.acquisition, bits=0))


# ----------------------------------------------------------------------------- GUM arithmetic against GTC


def test_welch_satterthwaite_and_coverage_factor_agree_with_gtc():
    c = [0.7, -1.3, 2.1, 0.05]
    u = [1.2e-3, 4.0e-4, 2.5e-4, 3.0e-2]
    nu = [4, 9, math.inf, 19]
    x = [ureal(1.0, ui, df) for ui, df in zip(u, nu)]
    y = sum(ci * xi for ci, xi in zip(c, x))
    uc, nu_eff = combine([ci * ui for ci, ui in zip(c, u)], nu)
    assert uc == pytest.approx(y.u, rel=1e-12)
    assert nu_eff == pytest.approx(y.df, rel=1e-10)
    assert welch_satterthwaite([ci * ui for ci, ui in zip(c, u)], nu) == pytest.approx(y.df, rel=1e-10)
    for df in (1.0, 3.5, 12.0, 250.0, nu_eff):
        assert coverage_factor(df) == pytest.approx(reporting.k_factor(df, 95), rel=1e-9)
    assert coverage_factor(math.inf) == pytest.approx(1.959963984540054, rel=1e-12)
    # only type B inputs: ν_eff infinite (GUM G.4.2)
    assert welch_satterthwaite([1.0, 2.0], [math.inf, math.inf]) == math.inf


def test_arithmetic_rejects_bad_input():
    with pytest.raises(ValueError, match="degrees of freedom"):
        welch_satterthwaite([1.0], [0.0])
    with pytest.raises(ValueError, match="shape"):
        welch_satterthwaite([1.0, 2.0], [3.0])
    with pytest.raises(ValueError, match="coverage_probability"):
        coverage_factor(10.0, 1.5)
    with pytest.raises(ValueError, match="step"):
        quantisation_variance(0.0, 1.0, 10)
    with pytest.raises(ValueError, match="samples"):
        quantisation_variance(1.0, 1.0, 0)
    with pytest.raises(TypeError, match="Scenario"):
        evaluate_gum("jjf2003")
    with pytest.raises(TypeError, match="quantisation_correlation"):
        evaluate_gum(load_scenario("ideal"), quantisation_correlation="yes")


def test_appendix_a_models_recombined_with_gtc():
    """The Appendix A inputs through their own measurement models, by GTC and by plansim."""
    # A.2, eq. (A.4): B = mean of 6 group outputs of u = 3.41e-5 each (type A), plus u1, u2 (type B)
    a2 = appendix_a_budget("A.2")
    readings = [ureal(0.0, 3.41e-5, 29) for _ in range(6)]
    mean = sum(readings) / 6
    assert a2.component("u3").gum_standard_uncertainty == pytest.approx(mean.u, rel=1e-12)
    b = mean + ureal(0.0, 1.0e-4) + ureal(0.0, 1.41e-4)
    same = math.sqrt(sum(c.gum_standard_uncertainty**2 for c in a2.components))
    assert same == pytest.approx(b.u, rel=1e-12)
    # A.3, eq. (A.6): gxx = (U1 − U2)/2
    a3 = appendix_a_budget("A.3")
    g = (ureal(0.0, 2.51e-3) - ureal(0.0, 2.51e-3)) / 2
    assert a3.component("u3").gum_standard_uncertainty == pytest.approx(g.u, rel=1e-12)
    # A.5, eq. (A.10) read in FS_a/ω²: p = U7 − U8
    a5 = appendix_a_budget("A.5")
    p = ureal(0.0, 2.51e-3) - ureal(0.0, 2.51e-3)
    assert a5.component("u3").gum_standard_uncertainty == pytest.approx(p.u, rel=1e-12)
    # the printed linear sums are larger than the GUM's
    for item in ("A.2", "A.3", "A.5"):
        c = appendix_a_budget(item).component("u3")
        assert c.combined_as_printed > c.gum_standard_uncertainty


@pytest.fixture(scope="module")
def white(linear):
    sc = white_noise_only(linear)
    return sc, evaluate_gum(sc)


def _segment_ureals(sc, channel, segments):
    """One ureal per segment mean of *channel*: u = N/√T, ν = n − 1 (type A)."""
    n = sc.noise.gyro_angle_random_walk[channel] if channel < 3 else sc.noise.accel_velocity_random_walk[channel - 3]
    out = []
    for k in segments:
        s = sc.schedule.segments[k]
        out.append(ureal(0.0, n / math.sqrt(s.dwell), s.samples - 1))
    return out


def test_a1_line_fit_model_agrees_with_gtc(white):
    """A.1 / §7.2.1: K from the least-squares line U = K X + b of the rate points (eq. (4)-(5))."""
    sc, gum = white
    for axis, name in enumerate(("Kgxx", "Kgyy", "Kgzz")):
        ks = [k for k in sc.schedule.select("rate") if sc.schedule.segments[k].group == axis]
        rates = [sc.schedule.segments[k].rate for k in ks]
        fit = tb.line_fit(rates, _segment_ureals(sc, axis, ks))
        slope = fit.a_b[1]
        budget = gum.budget(name)
        assert budget.contribution("white noise, gyros") == pytest.approx(slope.u, rel=1e-9)
        assert budget.combined_standard_uncertainty == pytest.approx(slope.u, rel=1e-9)
        assert budget.effective_dof == pytest.approx(slope.df, rel=1e-8)
        assert budget.coverage_factor == pytest.approx(reporting.k_factor(slope.df, 95), rel=1e-9)


def test_a2_mean_and_a3_half_difference_models_agree_with_gtc(white):
    """A.2: B = mean of the 6 groups (eq. (7), row 4 of A); A.3: g = (U_up − U_down)/(2 g_ref) (eq. (7))."""
    sc, gum = white
    idx = sc.schedule.select("multi_position")
    groups = {}
    for k in idx:
        groups.setdefault(sc.schedule.segments[k].group, []).append(k)
    g_ref = sc.reduction.reference_gravity
    for axis, bias in enumerate(("Bgx", "Bgy", "Bgz")):
        u = {grp: _segment_ureals(sc, axis, ks) for grp, ks in groups.items()}
        group_means = {grp: sum(v) / len(v) for grp, v in u.items()}
        b = sum(group_means.values()) / len(group_means)
        budget = gum.budget(bias)
        assert budget.combined_standard_uncertainty == pytest.approx(b.u, rel=1e-9)
        assert budget.effective_dof == pytest.approx(b.df, rel=1e-8)
        # the diagonal g-sensitivity: groups 2·axis+1 (axis up) and 2·axis+2 (axis down)
        up, down = group_means[2 * axis + 1], group_means[2 * axis + 2]
        g = (up - down) / (2 * g_ref)
        diag = gum.budget(f"g{'xyz'[axis]}{'xyz'[axis]}")
        assert diag.combined_standard_uncertainty == pytest.approx(g.u, rel=1e-9)
        assert diag.effective_dof == pytest.approx(g.df, rel=1e-8)


def test_a5_difference_model_agrees_with_gtc(white):
    """A.5 / §7.2.5: p_yx = (U8 − U7)/ω² (eq. (12)-(13), the model's sign)."""
    sc, gum = white
    for axis in range(3):
        segs = [k for k in sc.schedule.select("omega_squared") if sc.schedule.segments[k].group == axis]
        rest = [k for k in segs if sc.schedule.segments[k].rate == 0.0]
        turning = [k for k in segs if sc.schedule.segments[k].rate != 0.0]
        omega = sc.schedule.segments[turning[0]].rate
        for row in range(3):
            if row == axis:
                continue
            u7 = sum(_segment_ureals(sc, 3 + row, rest)) / len(rest)
            u8 = sum(_segment_ureals(sc, 3 + row, turning)) / len(turning)
            p = (u8 - u7) / omega**2
            budget = gum.budget(f"p{'xyz'[row]}{'xyz'[axis]}")
            assert budget.combined_standard_uncertainty == pytest.approx(p.u, rel=1e-9)
            assert budget.effective_dof == pytest.approx(p.df, rel=1e-8)


# ----------------------------------------------------------------------------- the model's pieces


def test_estimator_matrix_is_the_reduction(jjf):
    matrix = estimator_matrix(jjf)
    rng = np.random.default_rng(SEED)
    means = rng.normal(size=(5, len(jjf.schedule), 6))
    direct = reduce(means, jjf.schedule, jjf.reduction.reference_gravity, jjf.reduction.omega_squared_sign)
    assert np.allclose(np.einsum("psc,tsc->tp", matrix, means), direct, rtol=1e-12, atol=1e-12)


def test_quantisation_variance_has_appendix_a_and_dithered_limits():
    q = 2.0 / 2**12  # full scale 1: q = 2·FS/2^N, half-step δ = 1/2^N
    variance, fraction = quantisation_variance(q, 0.0, 3000)
    assert math.sqrt(variance) == pytest.approx(q / math.sqrt(12), rel=1e-12)
    assert math.sqrt(variance) == pytest.approx(appendix_a_budget("A.1").component("u2").value_per_reading, rel=1e-2)
    assert fraction == 1.0
    variance, fraction = quantisation_variance(q, 2.0 * q, 3000)  # σ = 2q: fully dithered
    assert variance == pytest.approx(q**2 / 12 / 3000, rel=1e-12)
    # the undithered fraction is the damped series, here its first term (6/π²)·exp(−4π²(σ/q)²)
    assert fraction == pytest.approx(6 / math.pi**2 * math.exp(-16 * math.pi**2), rel=1e-9)


def test_quantiser_bias_variance_matches_the_exact_moments():
    """B(σ) = Var over the offset of E[Q(μ + σZ)] − μ, against segment_path.quantised_gaussian_moments."""
    q = 1.0
    offsets = (np.arange(4000) + 0.5) / 4000  # μ uniform over one step (midpoint rule, exact to 1e-7)
    for sigma in (0.05, 0.15, 0.3):
        bias = np.array([quantised_gaussian_moments(mu, sigma, q)[0] - mu for mu in offsets])
        _, fraction = quantisation_variance(q, sigma, 1)
        assert fraction * q**2 / 12 == pytest.approx(np.mean(bias**2), rel=1e-4)


def test_quantisation_covariance_of_a_shared_offset():
    """Two noiseless segments: same code → fully correlated; half a step apart → −q²/24 (Bernoulli B₂);
    and against a direct simulation of the shared uniform offset."""
    q = 0.1
    cov = quantisation_covariance(q, np.array([0.0, 0.0, 0.5 * q, 0.3 * q]), np.zeros(4), np.full(4, 1000.0))
    assert cov[0, 1] == pytest.approx(q**2 / 12, rel=1e-6)
    assert cov[0, 2] == pytest.approx(-(q**2) / 24, rel=1e-6)
    f = 0.3
    assert cov[0, 3] == pytest.approx(q**2 / 12 * (1 - 6 * f * (1 - f)), rel=1e-6)
    rng = np.random.default_rng(SEED)
    offset = rng.uniform(0, q, 200_000)
    levels = np.array([0.0, 0.3 * q, 2.7 * q])
    x = offset[:, None] + levels[None, :]
    err = q * np.floor(x / q + 0.5) - x
    sample = np.cov(err, rowvar=False)
    model = quantisation_covariance(q, levels, np.zeros(3), np.ones(3))
    n = offset.size
    sd = np.sqrt((np.outer(np.diag(sample), np.diag(sample)) + sample**2) / n)
    assert np.all(np.abs(sample - model) <= Z * sd)


def test_drift_covariance_matches_simulated_segment_means(linear):
    """The derived covariance of the drift part of the segment means against the segment path."""
    n = linear.noise
    noise = dataclasses.replace(n, gyro_angle_random_walk=np.zeros(3), accel_velocity_random_walk=np.zeros(3),
                                gyro_bias_instability=np.full(3, 2.0 * math.pi / 180 / 3600),
                                gyro_rate_random_walk=np.full(3, 0.2 * math.pi / 180 / 3600 / 60),
                                gyro_markov_sigma=np.full(3, 1.0 * math.pi / 180 / 3600),
                                markov_correlation_time=300.0)
    sc = dataclasses.replace(white_noise_only(linear), noise=noise)
    trials = 3000
    res = run(sc, trials=trials, seed=SEED, path="segment", keep_segment_means=True)
    means = res["segment_mean"].values[:, :, 0]  # x gyro
    sample = np.cov(means, rowvar=False)
    model = drift_covariance(sc)[0]
    sd = np.sqrt((np.outer(np.diag(sample), np.diag(sample)) + sample**2) / trials)
    assert np.max(np.abs(sample - model) / sd) <= Z
    # the model is a covariance matrix
    assert np.min(np.linalg.eigvalsh(model)) >= -1e-12 * np.max(model)


# ----------------------------------------------------------------------------- budgets against Monte Carlo


def _kurtosis(e):
    c = e - e.mean(axis=0)
    return np.mean(c**4, axis=0) / np.mean(c**2, axis=0) ** 2


@pytest.mark.parametrize("name, groups", [("linear_gaussian", ("Kg", "Bg", "G", "Ka", "Ba", "P")),
                                          ("jjf2003", ("Kg", "Bg", "G"))])
def test_gum_standard_uncertainty_matches_monte_carlo(name, groups):
    """u_c against the Monte Carlo standard deviation, tolerance Z·sqrt((β₂ − 1)/(4n)) relative.

    jjf2003's accelerometers are left out: their 12-bit quantiser is not dithered and the units'
    offsets spread over only a quarter step, so the GUM's uniform-offset model does not hold
    there (the validation of test_mcm shows it)."""
    sc = load_scenario(name)
    gum = evaluate_gum(sc)
    trials = 20000
    e = run(sc, trials=trials, seed=SEED, path="segment")["error"].values
    s = e.std(axis=0, ddof=1)
    tolerance = Z * np.sqrt((_kurtosis(e) - 1) / (4 * trials))
    checked = [k for k, p in enumerate(PARAMETERS) if p.group in groups]
    ratio = s[checked] / gum.standard_uncertainty[checked]
    assert np.all(np.abs(ratio - 1) <= tolerance[checked]), dict(zip([PARAMETER_NAMES[k] for k in checked], ratio))


def test_budget_lines_are_complete_and_ordered(jjf_gum):
    for b in jjf_gum.budgets:
        contributions = [line.contribution for line in b.inputs]
        assert contributions == sorted(contributions, reverse=True)
        # lines of independent groups add in quadrature to u_c
        assert math.sqrt(sum(c**2 for c in contributions)) == pytest.approx(b.combined_standard_uncertainty, rel=1e-6)
        assert b.expanded_uncertainty == pytest.approx(b.coverage_factor * b.combined_standard_uncertainty)
        for line in b.inputs:
            assert line.evaluation in ("A", "B")
            assert (line.dof == math.inf) == (line.evaluation == "B")
    kgxx = jjf_gum.budget("Kgxx")
    names = {line.name for line in kgxx.inputs}
    assert {"rate error, systematic", "rate error, per point", "rate smoothness", "white noise, gyros",
            "drift, gyros", "quantisation, gyros"} <= names
    # the systematic rate error enters the scale factor with sensitivity K (relative error → K·ε)
    line = next(line for line in kgxx.inputs if line.name == "rate error, systematic")
    assert line.sensitivity == pytest.approx(kgxx.truth, rel=1e-6)
    assert jjf_gum.covariance.shape == (39, 39)
    r = jjf_gum.correlation()
    assert np.allclose(np.diag(r), 1.0) and np.all(np.abs(r) <= 1 + 1e-12)


def test_systematic_effects_against_closed_forms(jjf, jjf_gum):
    """Earth rate: its vertical component Ω sin φ flips with the up/down pair, so the diagonal
    g-sensitivity absorbs Kg_ii·Ω sin φ / g_ref (the up/down pairs of §7.2.2); lever arm: p_ij absorbs the r of
    accelerometer i through Ka (centripetal −ω²(r − (r·u)u), the ω² law of P)."""
    from plansim.model.environment import EARTH_RATE

    total, effects = systematic_effects(jjf)
    by_name = {name: bias for name, bias, _ in effects}
    earth = EARTH_RATE * math.sin(jjf.environment.latitude) / jjf.reduction.reference_gravity
    for axis in "xyz":
        scale = jjf.truth_nominal[PARAMETER_INDEX[f"Kg{axis}{axis}"]]  # the gyro sees Kg·Ω
        assert by_name["Earth rate"][PARAMETER_INDEX[f"g{axis}{axis}"]] == pytest.approx(scale * earth, rel=1e-6)
    lever = jjf.effects.accel_lever_arm
    Ka = unpack(jjf.truth_nominal)["Ka"]
    for row in range(3):
        for col in range(3):
            if row != col:  # p_row,col: turning about col; accelerometer row reads Ka·(−(r − (r·u)u))·ω²
                u = np.eye(3)[col]
                expected = Ka[row] @ -(lever[row] - (lever[row] @ u) * u)
                k = PARAMETER_INDEX[f"p{'xyz'[row]}{'xyz'[col]}"]
                assert by_name["accelerometer lever arm"][k] == pytest.approx(expected, rel=1e-9)
    assert np.allclose(total, jjf_gum.estimate)
    assert jjf_gum.budget("gzz").estimate == pytest.approx(jjf.truth_nominal[PARAMETER_INDEX["Kgzz"]] * earth, rel=1e-6)
    # the effects add up to y
    assert np.allclose(sum(bias for _, bias, _ in effects), total, rtol=0, atol=1e-15)


def test_reference_gravity_and_printed_sign_are_reported(jjf):
    g_std = 9.80665
    sc = dataclasses.replace(jjf, reduction=dataclasses.replace(jjf.reduction, reference_gravity=g_std,
                                                                   omega_squared_sign="as_printed"))
    _, effects = systematic_effects(sc)
    by_name = {name: bias for name, bias, _ in effects}
    ratio = jjf.environment.gravity / g_std
    k = PARAMETER_INDEX["Kaxx"]
    assert by_name["reference gravity"][k] == pytest.approx(jjf.truth_nominal[k] * (ratio - 1), rel=1e-3)
    # eq. (12)-(13) as printed return −(U8 − U7)/ω²: the bias is −2× the model-sign estimate
    model_total, _ = systematic_effects(dataclasses.replace(sc, reduction=dataclasses.replace(
        sc.reduction, omega_squared_sign="model")))
    for name in ("pxy", "pyx", "pzy"):
        k = PARAMETER_INDEX[name]
        estimate = jjf.truth_nominal[k] + model_total[k]
        assert by_name["omega-squared sign as printed"][k] == pytest.approx(-2 * estimate, rel=1e-9)


def test_ideal_scenario_has_an_empty_budget():
    gum = evaluate_gum(load_scenario("ideal"))
    for b in gum.budgets:
        assert b.combined_standard_uncertainty == 0.0 and b.inputs == ()
        assert b.effective_dof == math.inf
        assert abs(b.estimate) <= 1e-12 * max(abs(b.truth), 1.0)


# ----------------------------------------------------------------------------- Appendix A slips in the report


@pytest.fixture(scope="module")
def jjf_report():
    # the Appendix A checks do not depend on the Monte Carlo's length: a short run suffices
    return validate("jjf2003", trials_per_block=2000, max_trials=4000, seed=SEED)


def test_report_flags_the_linear_sum_slip_of_a2_a3_a5(jjf_report):
    items = {c.item: c for c in jjf_report.appendix_items}
    assert list(items) == ["A.1", "A.2", "A.3", "A.4", "A.5"]
    for item in ("A.2", "A.3", "A.5"):
        c = items[item]
        slips = [s for s in c.slips if s.startswith("linear-sum slip")]
        assert len(slips) == 1, c.slips
        # the GUM propagation of the same inputs gives the smaller value
        assert c.same_inputs_gum_U < c.printed_U
        assert c.same_inputs_gum_uc < c.printed_uc
    for item in ("A.1", "A.4"):
        assert not any(s.startswith("linear-sum slip") for s in items[item].slips)
        assert items[item].same_inputs_gum_uc == pytest.approx(items[item].printed_uc, rel=1e-2)
    assert items["A.2"].same_inputs_gum_U == pytest.approx(2 * math.sqrt(1e-4**2 + 1.41e-4**2 + 1.39e-5**2), rel=1e-2)
    # A.3: printed 1.1e-2 is k·u_c = 1.0046e-2 rounded up
    assert any("rounded up" in s and "0.011" in s for s in items["A.3"].slips)
    text = format_report(jjf_report, details=False)
    assert text.count("linear-sum slip") == 3


def test_report_shows_claimed_and_achieved_for_each_item(jjf_report, jjf):
    for c in jjf_report.appendix_items:
        budget = appendix_a_budget(c.item)
        assert c.claimed_U == budget.printed_expanded_uncertainty
        assert len(c.gum_U95) == len(c.mcm_U95) == len(budget.parameters)
        assert all(u > 0 for u in c.gum_U95 + c.mcm_U95)
        for name, achieved in zip(c.parameters, c.gum_U95):
            b = jjf_report.gum.budget(name)
            assert b.appendix_a.item == c.item
            assert achieved == pytest.approx(b.appendix_a.plansim_U95, rel=1e-12)
    # Appendix A claims are on the 27 parameters it covers, none on Ka and Ba
    claimed = {p.name for p in jjf_report.parameters if p.claimed_U is not None}
    assert claimed == {name for b in APPENDIX_A for name in b.parameters}


def test_type_b_degrees_of_freedom_from_a_stated_reliability(jjf):
    """GUM G.4.2: ν = ½(Δu/u)⁻²; Welch–Satterthwaite over the budget as GTC computes it."""
    gum = evaluate_gum(jjf, relative_uncertainty_of_u={"rate error, systematic": 0.25, "drift, gyros": 0.5})
    b = gum.budget("Kgxx")
    dofs = {line.name: line.dof for line in b.inputs}
    assert dofs["rate error, systematic"] == pytest.approx(8.0) and dofs["drift, gyros"] == pytest.approx(2.0)
    y = sum(ureal(0.0, line.contribution, line.dof) for line in b.inputs)
    assert b.effective_dof == pytest.approx(y.df, rel=1e-6)
    assert b.coverage_factor == pytest.approx(reporting.k_factor(y.df, 95), rel=1e-9)
    assert b.effective_dof < 100  # ν_eff falls from ~10⁶ to a few tens: k > 1.96
    with pytest.raises(ValueError, match="no input 'table wobble'"):
        evaluate_gum(jjf, relative_uncertainty_of_u={"table wobble": 0.1})
    with pytest.raises(ValueError, match="type A"):
        evaluate_gum(jjf, relative_uncertainty_of_u={"white noise, gyros": 0.1})


def test_gum_budget_for_gtc_ureals_of_a_whole_budget(jjf_gum):
    """The group-equivalent lines recombine to u_c as GTC recombines independent uncertain numbers."""
    b = jjf_gum.budget("Kgxx")
    y = sum(ureal(0.0, line.contribution, line.dof) for line in b.inputs)
    assert y.u == pytest.approx(b.combined_standard_uncertainty, rel=1e-6)
    assert GTC.dof(y) == pytest.approx(b.effective_dof, rel=1e-6)
