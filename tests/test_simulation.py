"""End-to-end simulation tests: closed forms, identities, reproducibility (JJF 2003-2022 §7.2)."""

from __future__ import annotations

import copy
import math
import tomllib

import numba
import numpy as np
import pytest

import plansim
from plansim.config import parse_scenario
from plansim.io.scenario_file import builtin_scenarios
from plansim.model.environment import EARTH_RATE
from plansim.model.parameters import PARAMETER_NAMES
from plansim.simulate.chunks import simulate_recording, simulate_segment_means


def ideal_document() -> dict:
    with open(builtin_scenarios()["ideal"], "rb") as fh:
        return tomllib.load(fh)


def scenario_with(**changes):
    """The ideal scenario with sections updated, e.g. scenario_with(environment={"earth_rate": True})."""
    doc = ideal_document()
    for section, values in changes.items():
        node = doc
        parts = section.split("__")
        for part in parts:
            node = node.setdefault(part, {})
        node.update(copy.deepcopy(values))
    return parse_scenario(doc)


def test_ideal_zero_noise_identity():
    """`plansim run ideal`: every estimate equals its truth to 1e-9 relative."""
    results = plansim.run("ideal", trials=4, seed=3)
    truth = results["truth"].values
    error = results["error"].values
    assert np.all(np.abs(error) <= 1e-9 * np.abs(truth)), PARAMETER_NAMES[int(np.argmax(np.abs(error / truth).max(0)))]


def test_same_seed_same_numbers_whatever_the_chunking_and_threads():
    sc = plansim.load_scenario("jjf2003")
    reference, truth_ref = simulate_segment_means(sc, 9, seed=11, chunk_size=256)
    for chunk in (1, 4):
        means, truth = simulate_segment_means(sc, 9, seed=11, chunk_size=chunk)
        np.testing.assert_array_equal(means, reference)
        np.testing.assert_array_equal(truth, truth_ref)
    threads = numba.get_num_threads()
    try:
        numba.set_num_threads(1)
        means, _ = simulate_segment_means(sc, 9, seed=11, chunk_size=3)
    finally:
        numba.set_num_threads(threads)
    np.testing.assert_array_equal(means, reference)
    other, _ = simulate_segment_means(sc, 9, seed=12)
    assert not np.array_equal(other, reference)


def test_recording_is_the_same_trial_as_in_the_monte_carlo():
    sc = plansim.load_scenario("jjf2003")
    means, truth = simulate_segment_means(sc, 3, seed=5)
    samples, seg_means, seg_truth = simulate_recording(sc, seed=5, trial=2)
    np.testing.assert_array_equal(seg_means, means[2])
    np.testing.assert_array_equal(seg_truth, truth[2])
    counts = [s.samples for s in sc.schedule.segments]
    first = np.cumsum([0] + counts[:-1])
    recomputed = np.array([samples[f:f + n].mean(axis=0) for f, n in zip(first, counts)])
    np.testing.assert_allclose(recomputed, seg_means, rtol=0, atol=1e-15)


def _white_noise_scenario(arw: str, vrw: str):
    return scenario_with(mimu__noise={"gyro_angle_random_walk": arw, "accel_velocity_random_walk": vrw})


def _check_std(errors: np.ndarray, expected_std: float, label: str):
    """Sample std against a closed form, tolerance 5 standard errors of a std: 5/sqrt(2(n-1))."""
    n = errors.size
    measured = errors.std(ddof=1)
    tolerance = 5.0 / math.sqrt(2.0 * (n - 1))
    assert abs(measured / expected_std - 1.0) < tolerance, f"{label}: {measured:.4g} vs {expected_std:.4g} (n={n})"
    # and no estimator bias beyond 5 standard errors of the mean
    assert abs(errors.mean()) < 5.0 * expected_std / math.sqrt(n), f"{label}: mean {errors.mean():.3g}"


@pytest.mark.slow
def test_white_noise_variances_follow_the_closed_forms():
    """White noise only: var(K) = σ²_mean / Σ(ω − ω̄)² (eq. (5)), var(B) = σ²_pos/12, var(g_ii) = σ²_pos/(4 g²),
    var(Ka_ii) likewise, var(p) = 2 σ²_point / ω⁴ (eq. (12)), with σ²_mean = N²/T for a white coefficient N
    over a T-second dwell (IEEE Std 952: σ²(τ) = N²/τ)."""
    arw = 0.15 * math.pi / 180 / 60  # rad/√s
    vrw = 0.012 / 60  # m/s/√s
    sc = _white_noise_scenario("0.15 deg/sqrt(h)", "0.012 m/s/sqrt(h)")
    trials = 300
    res = plansim.run(sc, trials=trials, seed=7)
    T = sc.schedule.segments[0].samples / sc.schedule.segments[0].sample_rate
    rates = np.array([s.rate for s in sc.schedule.segments if s.test == "rate" and s.group == 0])
    sxx = np.sum((rates - rates.mean()) ** 2)
    g = sc.reduction.reference_gravity
    omega = [s.rate for s in sc.schedule.segments if s.test == "omega_squared" and s.rate][0]
    err = res["error"]
    pool = lambda names: np.concatenate([err.sel(parameter=n).values for n in names])  # noqa: E731
    _check_std(pool(["Kgxx", "Kgyy", "Kgzz", "Kgxy", "Kgzx"]), arw / math.sqrt(T) / math.sqrt(sxx), "Kg")
    _check_std(pool(["Bgx", "Bgy", "Bgz"]), arw / math.sqrt(T) / math.sqrt(12), "Bg")
    _check_std(pool(["gxx", "gyy", "gzz", "gxy"]), arw / math.sqrt(T) / 2 / g, "G")
    _check_std(pool(["Kaxx", "Kayy", "Kazz"]), vrw / math.sqrt(T) / 2 / g, "Ka")
    _check_std(pool(["Bax", "Bay", "Baz"]), vrw / math.sqrt(T) / math.sqrt(12), "Ba")
    _check_std(pool(["pxy", "pyx", "pzx"]), vrw / math.sqrt(T) * math.sqrt(2) / omega**2, "P")


def test_earth_rate_is_confounded_with_the_diagonal_g_sensitivity():
    """JJF 2003 §7.2.2: the vertical Earth rate flips sign with the up/down pairs of §7.2.2.1 a), so eq. (7) gives
    ĝ_ii − g_ii = Kg_ii Ω_ie sin φ / g_ref exactly (the gyro sees the vertical Earth rate through its
    scale factor), while the horizontal part cancels in the 180° pairs."""
    sc = scenario_with(environment={"earth_rate": True})
    res = plansim.run(sc, trials=2, seed=1)
    vertical = EARTH_RATE * math.sin(sc.environment.latitude) / sc.reduction.reference_gravity
    for name, scale in (("gxx", "Kgxx"), ("gyy", "Kgyy"), ("gzz", "Kgzz")):
        expected = res["truth"].sel(parameter=scale).values * vertical
        np.testing.assert_allclose(res["error"].sel(parameter=name).values, expected, rtol=1e-8)
    for name in ("Bgx", "Bgy", "Bgz"):
        assert np.all(np.abs(res["error"].sel(parameter=name).values) < 1e-6 * vertical)
    # off-diagonal g: only the cross-coupling Kg_ij of the vertical Earth rate remains
    off = res["error"].sel(parameter="gxy").values
    expected_off = res["truth"].sel(parameter="Kgxy").values * vertical
    np.testing.assert_allclose(off, expected_off, rtol=1e-6)


def test_printed_sign_of_eq_12_returns_minus_p():
    """JJF 2003 §7.2.5.2: with eq. (2) of §5.2 as written, eq. (12)'s (U7 − U8)/ω² is −p; 'model' returns +p."""
    sc = scenario_with(reduction={"omega_squared_sign": "as_printed"})
    res = plansim.run(sc, trials=2, seed=1)
    for name in ("pxy", "pyx", "pzy"):
        np.testing.assert_allclose(res["estimate"].sel(parameter=name).values,
                                   -res["truth"].sel(parameter=name).values, rtol=1e-8)


def test_lever_arm_enters_p_as_minus_the_radius():
    """An accelerometer at r from the table axis feels −ω² r⊥ (same ω² law as p):
    p̂_yx − p_yx = −(Ka_yy r_y + Ka_yz r_z)."""
    r = np.array([0.003, 0.004, 0.002])
    row = [f"{v * 1000} mm" for v in r]
    sc = scenario_with(mimu__effects={"accel_lever_arm": [row, row, row]})
    res = plansim.run(sc, trials=1, seed=1)
    t = res["truth"].isel(trial=0)
    expected = -(t.sel(parameter="Kayy") * r[1] + t.sel(parameter="Kayz") * r[2])
    np.testing.assert_allclose(res["error"].sel(parameter="pyx").values, expected.values, rtol=1e-8)


def test_non_whole_turn_windows_leak_the_horizontal_earth_rate_into_cross_coupling():
    """Orientation follows the gimbal: a whole number of turns averages the horizontal Earth rate
    out of the cross-coupling columns; a window that is not a whole number of turns does not."""
    whole = {"rate_points": ["-36 deg/s", "36 deg/s", "72 deg/s"], "dwell": "30 s"}  # 3, 6 turns
    partial = {"rate_points": ["-37 deg/s", "37 deg/s", "72 deg/s"], "dwell": "30 s"}
    errs = {}
    for label, sched in (("whole", whole), ("partial", partial)):
        sc = scenario_with(environment={"earth_rate": True}, schedule=sched)
        res = plansim.run(sc, trials=2, seed=4)
        errs[label] = np.abs(res["error"].sel(parameter=["Kgyx", "Kgzx", "Kgxy", "Kgzy"]).values).max()
    horizontal = EARTH_RATE * math.cos(math.radians(39.9))
    assert errs["whole"] < 1e-9 * horizontal / math.radians(36)
    assert errs["partial"] > 1e-4 * horizontal / math.radians(37)


def test_blas_runs_on_one_thread_while_the_kernels_run_and_is_restored_after():
    """The engine's threads use every core; numpy's BLAS is held to one thread meanwhile (see
    plansim.simulate.chunks.iterate_chunks) and given its threads back when the last chunk is used."""
    from threadpoolctl import threadpool_info

    from plansim.simulate.chunks import iterate_chunks

    def blas_threads():
        return [info["num_threads"] for info in threadpool_info() if info["user_api"] == "blas"]

    before = blas_threads()
    if not before:
        pytest.skip("numpy reports no BLAS library to limit")
    during = [blas_threads() for _ in iterate_chunks(plansim.load_scenario("jjf2003"), 4, 1, chunk_size=2,
                                                     path="segment")]
    assert len(during) == 2 and all(threads == [1] * len(before) for threads in during)
    assert blas_threads() == before


@pytest.mark.parametrize("chunk_size", [1, 7, 333])
def test_estimates_are_bit_identical_whatever_the_chunk_size(chunk_size):
    """The reduction's rounding must not depend on how the trials are chunked (issue 9 §2)."""
    reference = plansim.run("jjf2003", trials=700, seed=4)
    chunked = plansim.run("jjf2003", trials=700, seed=4, chunk_size=chunk_size)
    for variable in ("truth", "estimate", "error"):
        assert np.array_equal(chunked[variable].values, reference[variable].values), variable


def test_a_trial_gives_the_same_bits_whatever_the_number_of_trials():
    """Trial i is reduced in the same fixed block shape at the same position, however many trials follow it."""
    many = plansim.run("jjf2003", trials=4100, seed=6)
    for trials in (1, 2, 4097):
        few = plansim.run("jjf2003", trials=trials, seed=6)
        assert np.array_equal(few["estimate"].values, many["estimate"].values[:trials]), trials


@pytest.mark.parametrize("trials, exception", [(0, ValueError), (-3, ValueError), (2.5, TypeError),
                                               (True, TypeError), ("10", TypeError), (10.0, TypeError)])
def test_run_rejects_a_bad_trial_count_naming_it(trials, exception):
    with pytest.raises(exception, match=r"trials = "):
        plansim.run("ideal", trials=trials, seed=1)


def test_a_run_closed_early_waits_for_one_slice_per_thread_not_a_chunk(monkeypatch):
    """Ctrl-C (or any early close of the chunk generator) cancels the queued slices of the next chunk and
    waits only for those already running: at most SLICE_TRIALS trials per thread, not a whole chunk
    (13.9 s of the sample path on the default scenario before chunks were sliced)."""
    import time

    from plansim.io.scenario_file import load_scenario
    from plansim.simulate import chunks

    simulated = []

    def slow_slice(self, first, key, means, truth):
        time.sleep(0.01)
        means[...] = 0.0
        truth[...] = 0.0
        simulated.append(means.shape[0])

    monkeypatch.setattr(chunks._PathKernels, "run_slice", slow_slice)
    monkeypatch.setattr(chunks, "compile_kernels", lambda calls: None)
    generator = chunks.iterate_chunks(load_scenario("ideal"), 3 * 4096, seed=1, chunk_size=4096,
                                      path="segment")
    next(generator)  # the first chunk is done and the second one queued
    generator.close()
    after_first = sum(simulated) - 4096
    assert 0 <= after_first <= 2 * numba.get_num_threads() * chunks.SLICE_TRIALS < 4096
