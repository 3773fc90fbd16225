"""pytest-benchmark suite. CI runs it once for correctness (``--benchmark-disable`` in pyproject);
``python -m pytest benchmarks --benchmark-enable`` measures. The thread count is pinned to the
machine's cores and every kernel is compiled (warmed up) before timing.

The figures quoted in README and docs/performance.md come from ``plansim bench``, which measures
them side by side in one run.
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

import plansim
from plansim.io.scenario_file import load_scenario
from plansim.simulate.chunks import simulate_segment_means


@pytest.fixture(scope="module")
def default_scenario():
    numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
    sc = load_scenario("jjf2003")
    simulate_segment_means(sc, 2, seed=1, path="sample")  # warm up (compile or load the cache)
    simulate_segment_means(sc, 2, seed=1, path="segment")
    return sc


def test_numpy_standard_normal_reference(benchmark):
    rng = np.random.default_rng(1)
    buffer = np.empty(65536)
    benchmark(rng.standard_normal, out=buffer)
    assert np.isfinite(buffer).all()


def test_sample_level_path(benchmark, default_scenario):
    means, truth = benchmark(simulate_segment_means, default_scenario, 8, 1, 8, None, "sample")
    assert means.shape == (8, len(default_scenario.schedule), 6) and np.isfinite(means).all()


def test_segment_statistics_path(benchmark, default_scenario):
    means, truth = benchmark(simulate_segment_means, default_scenario, 2000, 1, 2000, None, "segment")
    assert np.isfinite(means).all()


def test_complete_calibrations_default(benchmark, default_scenario):
    results = benchmark(plansim.run, default_scenario, trials=2000, seed=1)
    assert results.attrs["simulation_path"] == "segment-statistics"
    assert np.isfinite(results["error"].values).all()


def test_predict_default(benchmark, default_scenario):
    """The GUM prediction of the default schedule (plansim bench's predict_seconds)."""
    prediction = benchmark(plansim.predict, default_scenario)
    assert np.isfinite(prediction.u_predicted.values).all()


def test_bench_command_quick(capsys):
    """`plansim bench --quick --json` runs end to end and reports every documented figure."""
    import json

    from plansim.cli import main

    assert main(["bench", "--quick", "--json"]) == 0
    figures = json.loads(capsys.readouterr().out)
    for key in ("numpy_normal_per_s", "samples_per_s", "calibrations_per_s", "peak_rss_mb", "summary_peak_rss_mb",
                "summary_seconds", "cold_start_s", "warm_start_s", "seconds_per_trial", "predict_seconds",
                "predict_new_schedule_seconds", "sweep_seconds", "diagnose_seconds", "diagnose_effect_seconds"):
        assert key in figures
    assert figures["sweep_cells"] == 4 and figures["sweep_seconds"] > 0
    assert figures["diagnose_seconds"] > 0 and figures["diagnose_effect_seconds"] > 0
    assert figures["calibrations_per_s"] > 0 and figures["peak_rss_mb"] > 0 and figures["summary_peak_rss_mb"] > 0


@pytest.fixture(scope="module")
def move_rates():
    """A 2000-sample move (20 s at 100 Hz) of body rates, rad/s, and its sample intervals."""
    from plansim.kernels.trajectory import integrate_rotation

    rng = np.random.default_rng(3)
    rates, dt = rng.normal(size=(2000, 3)), np.full(2000, 0.01)
    integrate_rotation(rates, dt, np.array([0.0, 0.0, 1.0]), np.empty((3, 3)), np.empty(3), np.empty((2000, 3, 3)))
    return rates, dt


def test_move_rotation_forward_only(benchmark, move_rates):
    """One evaluation of a move's residual in the moves' search (``plansim.kernels.trajectory.rotate``)."""
    from plansim.kernels.trajectory import rotate

    rates, dt = move_rates
    end = np.empty(3)
    benchmark(rotate, rates, dt, np.array([0.0, 0.0, 1.0]), np.empty((3, 3)), end)
    assert abs(np.linalg.norm(end) - 1.0) < 1e-12


def test_move_rotation_with_sensitivities(benchmark, move_rates):
    """The same with the sensitivities the Jacobian needs (``integrate_rotation``): about twice ``rotate``."""
    from plansim.kernels.trajectory import integrate_rotation

    rates, dt = move_rates
    end, sensitivity = np.empty(3), np.empty((rates.shape[0], 3, 3))
    benchmark(integrate_rotation, rates, dt, np.array([0.0, 0.0, 1.0]), np.empty((3, 3)), end, sensitivity)
    assert abs(np.linalg.norm(end) - 1.0) < 1e-12 and np.isfinite(sensitivity).all()


def test_fit_hand_session_with_moves(benchmark):
    """``plansim fit`` of a simulated 30-pose hand-held session, the moves' search included."""
    import math

    from plansim.fit import fit_recording
    from plansim.fit.site import Site
    from plansim.io.recording import Recording
    from plansim.simulate.hand_session import consumer_unit, hand_session, spread_poses

    site = Site(math.radians(45.0), 100.0, earth_rate=False)
    s = hand_session(consumer_unit(1000), spread_poses(30, seed=1000), seed=1000, gravity=site.gravity,
                     gyro_noise=8.7e-4, accel_noise=9.8e-3)
    recording = Recording(s.samples, s.schedule, {"source": "simulated"}, timestamps=s.time)
    fit_recording(recording, site)  # warm up
    result = benchmark.pedantic(fit_recording, args=(recording, site), rounds=3, iterations=1)
    assert result.moves is not None and {"Kgxx", "Kgyy", "Kgzz"} <= set(result.identified)
