"""Optimal design (plansim.design): the criteria, the multiplicative algorithm and its equivalence-theorem
certificate, rounding and exchange, against closed forms and against pydoe.

Closed forms (Atkinson, Donev & Tobias 2007, §11.3; Pukelsheim 1993, §9.5): on [−a, a] the D-optimal designs
for a polynomial in ω of degree 1, 2, 3 put equal weights on {±a}, {−a, 0, a} and {±a, ±a/√5} (the
support of degree d is ±a and the roots of the derivative of the Legendre polynomial P_d).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plansim.design.algorithms import (
    certificate,
    efficient_rounding,
    exchange,
    multiplicative,
    refine_support,
)
from plansim.design.criteria import Criterion, information


def polynomial(degree: int, scale: float = 1.0):
    """Information of one observation at ω of a polynomial of *degree* in ω/scale (unit noise)."""
    def regressor(x):
        f = (x / scale) ** np.arange(degree + 1)
        return np.outer(f, f)
    return regressor


def blocks_on(grid, degree):
    f = np.vander(np.asarray(grid), degree + 1, increasing=True)
    return np.einsum("ij,ik->ijk", f, f)


@pytest.mark.parametrize("degree, support", [
    (1, [-1.0, 1.0]),
    (2, [-1.0, 0.0, 1.0]),
    (3, [-1.0, -1.0 / math.sqrt(5.0), 1.0 / math.sqrt(5.0), 1.0]),
])
@pytest.mark.parametrize("a", [1.0, 2.0])  # rate points in rad/s: ±2 rad/s ≈ ±115 °/s
def test_d_optimal_rate_points_are_the_closed_form(degree, support, a):
    # the grid (0.01·a apart) does not hold ±a/√5; the continuous stage must find it to 1e-9
    x, design, cert = refine_support(polynomial(degree, a), np.linspace(-a, a, 201))
    np.testing.assert_allclose(x, a * np.array(support), rtol=0, atol=1e-9 * a)
    np.testing.assert_allclose(design.weights, 1.0 / len(support), rtol=0, atol=1e-9)
    # the equivalence theorem: φ ≤ p everywhere on the grid, with equality on the support
    assert cert.bound == degree + 1
    assert cert.efficiency_bound >= 1 - 1e-9
    assert cert.support_gap <= 1e-9


def test_a_optimal_quadratic_matches_a_direct_minimisation():
    # A-optimal for a quadratic on [−1, 1]: support {−1, 0, 1}, weights (w, 1 − 2w, w) with w minimising
    # tr M(w)⁻¹; found here independently by a one-dimensional minimisation
    from scipy.optimize import minimize_scalar

    def trace(w):
        M = information(blocks_on([-1.0, 0.0, 1.0], 2), [w, 1 - 2 * w, w])
        return np.trace(np.linalg.inv(M))

    w = minimize_scalar(trace, bounds=(1e-3, 0.499), method="bounded", options={"xatol": 1e-12}).x
    x, design, cert = refine_support(polynomial(2), np.linspace(-1, 1, 201), "A")
    np.testing.assert_allclose(x, [-1.0, 0.0, 1.0], atol=1e-9)
    np.testing.assert_allclose(design.weights, [w, 1 - 2 * w, w], atol=1e-6)
    assert cert.efficiency_bound >= 1 - 1e-8


def test_c_optimal_slope_puts_all_weight_on_the_ends():
    # the variance of the slope of a line is smallest with half the points at each end (Elfving)
    grid = np.linspace(-1, 1, 41)
    design = multiplicative(blocks_on(grid, 1), Criterion("c", c=[0.0, 1.0]), tolerance=1e-6)
    assert design.weights[[0, -1]].sum() > 0.999  # what is left inside vanishes as the tolerance does
    np.testing.assert_allclose(design.weights[[0, -1]], 0.5, atol=1e-3)
    assert design.certificate.efficiency_bound >= 1 - 1e-6


def test_costs_make_weights_fractions_of_the_total_cost():
    # two candidates that each identify one parameter, one three times as costly: D puts half the *cost* on
    # each (each parameter gets half the budget), so the costly one is recorded a third as often
    blocks = np.array([np.diag([1.0, 0.0]), np.diag([0.0, 1.0])]) + 1e-300
    design = multiplicative(blocks, "D", costs=[1.0, 3.0], tolerance=1e-12)
    np.testing.assert_allclose(design.weights, [0.5, 0.5], atol=1e-12)
    np.testing.assert_allclose(design.units(8.0), [4.0, 4.0 / 3.0])


def test_certificate_bounds_the_efficiency_of_a_poor_design():
    grid = np.linspace(-1, 1, 21)
    blocks = blocks_on(grid, 2)
    best = multiplicative(blocks, "D", tolerance=1e-10)
    uniform = np.full(grid.size, 1.0 / grid.size)
    cert = certificate(blocks, uniform, Criterion("D"))
    efficiency = Criterion("D").efficiency(information(blocks, uniform), best.information)
    assert not cert.optimal
    assert cert.efficiency_bound <= efficiency + 1e-12 < 1.0  # the bound is a lower bound (Pukelsheim 5.15)


@pytest.mark.parametrize("n", [7, 10, 13])
def test_efficient_rounding_sums_to_n_and_follows_the_weights(n):
    w = np.array([0.5, 0.0, 0.3, 0.2])
    counts = efficient_rounding(w, n)
    assert counts.sum() == n and counts[1] == 0
    assert np.all(np.abs(counts - n * w) <= 1.0 + 1e-12)


def test_exchange_never_worsens_and_finds_the_exact_optimum_for_n_equal_p():
    grid = np.linspace(-1, 1, 11)
    blocks = blocks_on(grid, 2)
    start = np.zeros(grid.size, dtype=int)
    start[[3, 5, 6]] = 1  # a poor 3-point design
    counts = exchange(blocks, start, "D")
    assert counts.sum() == 3
    assert set(grid[counts > 0]) == {-1.0, 0.0, 1.0}


@pytest.mark.parametrize("bad, message", [
    (np.ones((2, 2)), "shape"),
    (np.array([[[1.0, 2.0], [0.0, 1.0]]]), "symmetric"),
    (np.full((1, 2, 2), np.nan), "finite"),
])
def test_bad_candidates_are_refused(bad, message):
    with pytest.raises(ValueError, match=message):
        multiplicative(bad)


def test_unidentifiable_candidates_are_refused_with_the_reason():
    with pytest.raises(ValueError, match="cannot identify"):
        multiplicative(blocks_on([0.5, 0.5, 0.5], 1))


def test_criterion_arguments_are_checked():
    with pytest.raises(ValueError, match="allowed: D, A, c"):
        Criterion("E")
    with pytest.raises(ValueError, match="required"):
        Criterion("c")
    with pytest.raises(ValueError, match="3 entries"):
        Criterion("c", c=[1.0, 0.0]).value(np.eye(3))


# ------------------------------------------------------------------------------------- against pydoe
pydoe = pytest.importorskip("pydoe", reason="pydoe (test extra) is not installed")


def test_criteria_are_pydoes():
    rng = np.random.default_rng(7)
    for _ in range(5):
        F = rng.normal(size=(9, 4))
        M = F.T @ F / 9
        c = rng.normal(size=4)
        assert math.isclose(np.exp(-Criterion("D").value(M)), pydoe.d_optimality(M), rel_tol=1e-12)
        assert math.isclose(Criterion("A").value(M), -pydoe.a_optimality(M), rel_tol=1e-12)
        assert math.isclose(Criterion("c", c=c).value(M), -pydoe.c_optimality(M, c), rel_tol=1e-12)


@pytest.mark.parametrize("degree, n", [(1, 2), (2, 3), (3, 4), (3, 6), (4, 5)])
def test_exact_rate_point_designs_match_pydoe(degree, n):
    # the exact D-optimal n-point design on a 21-point rate grid, by efficient rounding of the approximate
    # optimum and exchange, against pydoe's Fedorov exchange on the same grid: the same criterion to 1e-9.
    # (pydoe's designs do not repeat a point; with more points than the optimum's support, e.g. n = 7 for a
    # cubic, ours repeats one and is better — so the comparison is for n ≤ the support.)
    grid = np.linspace(-1.0, 1.0, 21)
    blocks = blocks_on(grid, degree)
    approximate = multiplicative(blocks, "D", tolerance=1e-7)
    counts = exchange(blocks, efficient_rounding(approximate.weights, n), "D")
    ours = math.exp(-Criterion("D").value(information(blocks, counts / n)))
    _, info = pydoe.optimal_design(grid[:, None], n_points=n, degree=degree, criterion="D", method="fedorov")
    assert math.isclose(ours, info["score"], rel_tol=1e-9)


# ------------------------------------------------------------------------------------- the MIMU's schedules
import dataclasses  # noqa: E402

import plansim  # noqa: E402
from plansim.design.alias import EFFECTS, alias_matrix  # noqa: E402
from plansim.design.catalogue import (  # noqa: E402
    Candidate,
    candidate_information,
    default_candidates,
    select_parameters,
)
from plansim.design.schedule_design import (  # noqa: E402
    design_efficiency,
    exact_design,
    optimal_design,
    refine_dwells,
)

#: a table without position errors: the closed form of the multi-position design assumes none
PERFECT_TABLE = ['turntable.position_accuracy="0 arcsec"', 'turntable.position_repeatability="0 arcsec"']


def multi_position_only(scenario):
    return dataclasses.replace(scenario.schedule, segments=tuple(
        s for s in scenario.schedule.segments if s.test == "multi_position"))


@pytest.mark.parametrize("positions", [6, 12])
def test_appendix_c_positions_are_d_optimal_for_the_accelerometers(positions):
    # Ka and Ba from the accelerometers at rest: regressors (a, 1) with a = g·u; any design whose directions u
    # have second moment I/3 and mean 0 has φ(u) = 1 + 3|u|² = 4 = p per channel on the whole sphere, so the
    # 6 and 12 positions of Appendix C are D-optimal among all poses, tilted ones included (efficiency 1)
    scenario = plansim.load_scenario("jjf2003", PERFECT_TABLE + [f"schedule.positions={positions}"])
    static = [c for c in default_candidates(scenario, dwells=(30.0,)) if c.kind != "rate"]
    efficiency, best = design_efficiency(scenario, multi_position_only(scenario), "D", ["Ka", "Ba"],
                                         ["ax", "ay", "az"], candidates=static)
    assert best.design.certificate.efficiency_bound >= 1 - 1e-6
    assert efficiency == pytest.approx(1.0, abs=1e-9)


def test_table_position_errors_make_tilted_poses_better_for_the_accelerometers():
    # with JJF 2003 Table 1's position errors a horizontal accelerometer reads g·δ of a setting that does not
    # average: the axis-aligned poses lose efficiency against poses tilted 45° (a finding, docs/planning.md)
    scenario = plansim.load_scenario("jjf2003")
    static = [c for c in default_candidates(scenario, dwells=(30.0,)) if c.kind != "rate"]
    efficiency, best = design_efficiency(scenario, multi_position_only(scenario), "D", ["Ka", "Ba"],
                                         ["ax", "ay", "az"], candidates=static)
    assert efficiency < 0.9
    assert best.support[0][0].kind == "tilted"


def test_information_is_the_jacobian_weighted_by_the_noise():
    scenario = plansim.load_scenario("jjf2003")
    info = candidate_information(scenario, default_candidates(scenario, dwells=(10.0, 300.0)))
    blocks = info.blocks()
    k = 5
    expected = info.jacobian[k].T @ np.linalg.solve(info.covariance[k], info.jacobian[k])
    np.testing.assert_allclose(blocks[k], expected, rtol=1e-10, atol=1e-12 * np.abs(expected).max())
    # a longer dwell lowers the white noise of the mean but not its drift: the variance falls by less than 30×
    short = [i for i, c in enumerate(info.candidates) if c.kind == "pose" and c.dwell == 10.0][0]
    long = [i for i, c in enumerate(info.candidates) if c.kind == "pose" and c.dwell == 300.0][0]
    ratio = info.covariance[short, 0, 0] / info.covariance[long, 0, 0]
    assert 1.0 < ratio < 30.0
    np.testing.assert_allclose(info.costs, [c.settle + c.dwell for c in info.candidates])


def test_optimal_design_is_certified_and_exact_design_keeps_the_budget():
    scenario = plansim.load_scenario("jjf2003")
    result = optimal_design(scenario, "D")
    assert result.design.certificate.efficiency_bound >= 1 - 1e-4
    ds = result.to_dataset()
    assert ds.time_fraction.sum() == pytest.approx(1.0)
    assert float(ds.derivative.max()) <= 1 / (1 - 1e-4)
    schedule = exact_design(result, table_time=3600.0)
    assert schedule.duration <= 3600.0 * 1.05  # rounding to whole segments may add one segment's time
    c = optimal_design(scenario, "c", c="Kgxx")
    kinds = {cand.kind for cand, w in c.support if w > 0.01}
    assert "rate" in kinds  # the scale factor is measured by turning


def test_the_best_dwell_of_a_pose_is_the_closed_form():
    """The dwell as a continuous variable. One gyro's bias from one pose, white noise N and a rate random walk K:
    the mean's variance is N²/T + K²T/3 (IEEE Std 952, the Allan variance at τ = T) and a segment costs s + T, so
    the information per second 1/((N²/T + K²T/3)(s + T)) is largest where 2cT³ + c·s·T² − N²s = 0, c = K²/3
    (about 60 s here: N = 0.15 °/√h, K = 3.5e-7 rad/s/√s, s = 10 s). The grid 10/30/100/300 s puts its weight on
    100 s; the continuous design finds the root to 0.2 s (the drift is a held process advanced every 0.1 s and the
    segments hold whole samples, so the information steps at that scale), certified by the equivalence theorem,
    and it is better than the grid's."""
    base = plansim.load_scenario("linear_gaussian")
    K = 3.5e-7
    noise = dataclasses.replace(base.noise, gyro_bias_instability=np.zeros(3), gyro_rate_random_walk=np.full(3, K),
                                gyro_markov_sigma=np.zeros(3))
    scenario = dataclasses.replace(base, noise=noise)
    N, settle = float(noise.gyro_angle_random_walk[0]), scenario.schedule.segments[0].settle
    candidates = [Candidate("pose", "+z", 0.0, 0.0, dwell, settle) for dwell in (10.0, 30.0, 100.0, 300.0)]
    options = dict(parameters=["Bgx"], channels=["gx"], candidates=candidates)
    grid = optimal_design(scenario, "D", **options)
    assert [c.dwell for c, w in grid.support] == [100.0]
    c = K**2 / 3.0
    roots = np.roots([2.0 * c, c * settle, 0.0, -(N**2) * settle])
    best = float(roots[np.argmin(np.abs(roots.imag))].real)
    assert 50.0 < best < 70.0
    free = optimal_design(scenario, "D", **options, continuous_dwell=True)
    (cand, weight), = free.support
    assert cand.dwell == pytest.approx(best, abs=0.2) and weight == pytest.approx(1.0)
    assert free.design.certificate.efficiency_bound >= 1 - 1e-4
    assert free.design.criterion.value(free.design.information) < grid.design.criterion.value(grid.design.information)
    with pytest.raises(ValueError, match="bounds"):
        refine_dwells(scenario, grid, bounds=(30.0, 10.0))
    with pytest.raises(ValueError, match="rounds"):
        refine_dwells(scenario, grid, rounds=0)


def test_continuous_dwells_for_the_gyro_biases_lie_between_the_grids_points():
    """The default scenario's gyro biases (D on Bg, gyro channels): on the grid every support point dwells 30 s;
    free, the bias instability's floor and the 10 s settling put them at about 24 s, a dwell the grid does not have,
    with the certificate holding over every dwell of the support's poses."""
    scenario = plansim.load_scenario("jjf2003")
    free = optimal_design(scenario, "D", parameters="Bg", channels=["gx", "gy", "gz"], continuous_dwell=True)
    dwells = {round(c.dwell, 6) for c, w in free.support}
    assert all(10.0 < d < 30.0 for d in dwells), dwells
    assert free.design.certificate.efficiency_bound >= 1 - 1e-4


@pytest.mark.parametrize("bad, message", [
    (dict(criterion="E"), "allowed: D, A, c"),
    (dict(parameters=["Kgxq"]), "Kgxq"),
    (dict(channels=["gw"]), "gw"),
    (dict(criterion="c", c="Kg"), "one parameter"),
])
def test_design_arguments_are_checked(bad, message):
    with pytest.raises(ValueError, match=message):
        optimal_design(plansim.load_scenario("ideal"), **bad)


def test_select_parameters_takes_names_and_groups():
    assert list(select_parameters(["Bg", "Kgxx"])) == [0, 9, 10, 11]


def test_vertical_earth_rate_aliases_into_g_ii_in_a_static_schedule():
    # JJF 2003's multi-position estimate of g_ii: gyro i up and down reads ±(g·g_ii + Kg_ii·Ω_U), so the
    # specification's estimator returns g_ii + Kg_ii·Ω_U/g_ref: the alias is Kg_ii/g_ref per rad/s
    scenario = plansim.load_scenario("jjf2003")
    spec = alias_matrix(scenario, estimator="jjf2003")
    names = [p.name for p in plansim.model.parameters.PARAMETERS]
    e = list(EFFECTS).index("earth_rate_up")
    for axis in "xyz":
        kg = scenario.truth_nominal[names.index(f"Kg{axis}{axis}")]
        assert spec.alias[e, names.index(f"g{axis}{axis}")] == pytest.approx(
            kg / scenario.reduction.reference_gravity, rel=1e-6)
    # in a static schedule no fit can separate it: the rates would, and are named
    static = alias_matrix(scenario, multi_position_only(scenario), estimator="wls")
    assert not static.separable[e]
    assert static.separated_by[e] and static.separated_by[e][0][0].startswith("rate")
    # with the rate test in the schedule it is separable
    assert alias_matrix(scenario, estimator="wls").separable[e]


def test_lever_arm_aliases_into_p_in_the_omega_squared_test():
    # accelerometer i at r from the table axis reads −ω²·r_⊥ (centripetal), the ω² law of p: the estimate of
    # p_ij (accelerometer i, rate about j) moves by −1 (m/s² per (rad/s)²) per metre of r_i
    scenario = plansim.load_scenario("jjf2003")
    spec = alias_matrix(scenario, estimator="jjf2003")
    names = [p.name for p in plansim.model.parameters.PARAMETERS]
    e = list(EFFECTS).index("lever_arm_x")
    assert spec.alias[e, names.index("pxy")] == pytest.approx(-1.0, rel=1e-2)
    assert spec.alias[e, names.index("pxz")] == pytest.approx(-1.0, rel=1e-2)
    assert not alias_matrix(scenario, multi_position_only(scenario), estimator="wls").separable[e]
