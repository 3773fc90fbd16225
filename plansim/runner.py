"""The orchestrator: scenario -> Monte Carlo calibrations -> self-describing results; one trial -> a recording.

``run`` simulates *trials* calibrations of the scenario, reduces each with the JJF 2003 formulas
and returns an :class:`xarray.Dataset` with ``truth``, ``estimate`` and ``error`` over
(``trial``, ``parameter``); parameter labels are the specification's symbols, values are SI with a
``units`` attribute, and the provenance (package version, scenario, seed, path) is in ``attrs``.
``validate`` and ``adaptive_monte_carlo`` hand :mod:`plansim.uncertainty` a simulate callable
built on ``run`` (:func:`error_simulator`), so the uncertainty layer never imports the runner.
"""

from __future__ import annotations

import datetime as _dt
import math
from typing import TYPE_CHECKING

import numpy as np
import tomli_w
import xarray as xr

import plansim
from plansim.config import Scenario
from plansim.estimate import reduce, reduction_matrix
from plansim.io.recording import UNITS_DESCRIPTION, Recording, plansim_version
from plansim.io.scenario_file import load_scenario
from plansim.kernels.layout import CHANNELS
from plansim.model.parameters import N_PARAMETERS, PARAMETER_NAMES, PARAMETERS
from plansim.simulate.chunks import ProgressCallback, iterate_chunks, simulate_recording
from plansim.simulate.paths import PATH_NAMES, choose_path

if TYPE_CHECKING:  # imported where used: `plansim run` does not load the uncertainty layer
    from plansim.uncertainty.monte_carlo import CalibrationMonteCarlo
    from plansim.uncertainty.validation import ValidationReport


def _scenario_of(scenario: Scenario | str) -> Scenario:
    if isinstance(scenario, Scenario):
        return scenario
    if isinstance(scenario, str):
        return load_scenario(scenario)
    raise TypeError(f"scenario = {scenario!r}: expected a Scenario, a built-in scenario name or a TOML path")


def run(scenario: Scenario | str = "jjf2003", trials: int | None = None, seed: int | None = None,
        chunk_size: int = 4096, progress: ProgressCallback | None = None,
        keep_segment_means: bool = False, path: str = "auto") -> xr.Dataset:
    """Monte Carlo of the scenario's calibration.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario object, a built-in name (``plansim scenarios``) or a TOML path.
    trials, seed : int, optional
        Override the scenario's ``[monte_carlo]`` values.
    chunk_size : int
        Trials per kernel call; results do not depend on it.
    progress : callable, optional
        ``progress(done, total)`` after each chunk.
    keep_segment_means : bool
        Also return the mean output of every segment (trial × segment × channel).
    path : {"auto", "sample", "segment"}
        Simulation path. ``auto`` takes the segment-statistics path only where it is exact
        (:func:`plansim.simulate.paths.segment_path_exactness`); the path used and, if the
        segment path was not exact, why, are in ``attrs``.

    Returns
    -------
    xarray.Dataset
        ``truth``, ``estimate``, ``error`` (= estimate − truth) over (trial, parameter), SI.
    """
    sc = _scenario_of(scenario)
    trials = sc.trials if trials is None else trials
    seed = sc.seed if seed is None else seed
    chosen, reasons = choose_path(sc, path)
    # reduce chunk by chunk: memory beyond the (trials × 39) results is bounded by chunk_size
    truth = np.empty((trials, N_PARAMETERS))
    estimate = np.empty((trials, N_PARAMETERS))
    means = np.empty((trials, len(sc.schedule), 6)) if keep_segment_means else None
    # the JJF 2003 formulas are linear in the segment means: one matrix product per chunk
    matrix = reduction_matrix(sc.schedule, sc.reduction.reference_gravity, sc.reduction.omega_squared_sign)
    for start, stop, m, t in iterate_chunks(sc, trials, seed, chunk_size, chosen, progress):
        truth[start:stop] = t
        if matrix is not None:
            np.matmul(m.reshape(stop - start, -1), matrix, out=estimate[start:stop])
        else:
            estimate[start:stop] = reduce(m, sc.schedule, sc.reduction.reference_gravity,
                                          sc.reduction.omega_squared_sign)
        if means is not None:
            means[start:stop] = m
    results = results_dataset(sc, truth, estimate, seed, means)
    results.attrs["simulation_path"] = PATH_NAMES[chosen]
    results.attrs["simulation_path_requested"] = path
    results.attrs["segment_path_not_exact_because"] = "; ".join(reasons) if reasons else "(exact)"
    return results


def results_dataset(sc: Scenario, truth: np.ndarray, estimate: np.ndarray, seed: int,
                    segment_means: np.ndarray | None = None) -> xr.Dataset:
    """Wrap the arrays of a run as a self-describing Dataset."""
    n = truth.shape[0]
    coords = {
        "trial": ("trial", np.arange(n), {"long_name": "Monte Carlo trial (one simulated calibration)"}),
        "parameter": ("parameter", list(PARAMETER_NAMES), {"long_name": "JJF 2003 parameter symbol"}),
        "group": ("parameter", [p.group for p in PARAMETERS], {"long_name": "matrix of eq. (1)/(2)"}),
        "units": ("parameter", [p.si_unit for p in PARAMETERS], {"long_name": "SI unit of the parameter"}),
        "display_unit": ("parameter", [p.display_unit for p in PARAMETERS]),
        "display_factor": ("parameter", [p.display_factor for p in PARAMETERS],
                           {"long_name": "SI value / display_factor = value in display_unit"}),
        "long_name": ("parameter", [p.long_name for p in PARAMETERS]),
    }
    common = {"units": "SI (per parameter: see the 'units' coordinate)"}
    data = {
        "truth": (("trial", "parameter"), truth, {**common, "long_name": "true parameter of the simulated unit"}),
        "estimate": (("trial", "parameter"), estimate,
                     {**common, "long_name": "JJF 2003 estimate from the simulated recording"}),
        "error": (("trial", "parameter"), estimate - truth, {**common, "long_name": "estimation error (estimate − truth)"}),
    }
    if segment_means is not None:
        coords["segment"] = ("segment", [s.label for s in sc.schedule.segments])
        coords["channel"] = ("channel", list(CHANNELS))
        data["segment_mean"] = (("trial", "segment", "channel"), segment_means,
                                {"units": "rad/s (gyro), m/s^2 (accelerometer)", "long_name": "mean output, eq. (3)"})
    attrs = {
        "title": f"plansim Monte Carlo of scenario {sc.name!r}",
        "scenario": sc.name,
        "scenario_description": sc.description,
        "scenario_toml": tomli_w.dumps(sc.document),
        # NetCDF-3 attributes hold 32-bit integers only: larger seeds are kept as text
        "seed": int(seed) if int(seed) <= 2**31 - 1 else str(int(seed)),
        "trials": int(n),
        "simulation_path": "sample-level",
        "plansim_version": plansim.__version__,
        "reference_gravity_m_s2": float(sc.reduction.reference_gravity),
        "reference_gravity_choice": sc.reduction.reference_gravity_label,
        "local_gravity_m_s2": float(sc.environment.gravity),
        "latitude_deg": math.degrees(sc.environment.latitude),
        "created_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
    }
    return xr.Dataset(data, coords=coords, attrs=attrs)


def simulate_and_record(scenario, seed: int, trial: int = 0) -> Recording:
    """Simulate one trial of *scenario* and return every raw sample as a :class:`Recording`.

    Parameters
    ----------
    scenario : plansim.config.Scenario
        The simulated world and schedule.
    seed : int
        Root seed, >= 0 (the same as for :func:`run`).
    trial : int
        Trial number, >= 0; the recording holds the same numbers that trial gives in a Monte Carlo run.

    Returns
    -------
    Recording
        ``attrs`` holds ``plansim_version``, ``scenario``, ``seed``, ``trial``, ``source = "simulated"``
        and ``units``. The true parameters of the simulated unit are not kept; call
        :func:`plansim.simulate.chunks.simulate_recording` for them.
    """
    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario: expected a plansim Scenario (see plansim.io.scenario_file.load_scenario), "
                        f"got {type(scenario).__name__}")
    samples, _segment_means, _truth = simulate_recording(scenario, seed, trial)
    attrs = {"plansim_version": plansim_version(), "scenario": scenario.name, "seed": int(seed),
             "trial": int(trial), "source": "simulated", "units": UNITS_DESCRIPTION}
    return Recording(samples=samples, schedule=scenario.schedule, attrs=attrs)

def error_simulator(scenario: Scenario, path: str = "auto"):
    """The scenario's calibration as ``simulate(trials, seed) -> (trials, 39)`` errors, and the name of its path.

    Parameters
    ----------
    scenario : Scenario
    path : {"auto", "sample", "segment"}
        As in :func:`run`.

    Returns
    -------
    simulate : callable
        ``run(scenario, trials, seed, path)["error"].values``: estimate − truth, SI.
    path_name : str
        The simulation path ``run`` takes for this scenario (its ``attrs["simulation_path"]``).
    """
    chosen, _ = choose_path(scenario, path)

    def simulate(trials: int, seed: int) -> np.ndarray:
        return run(scenario, trials=trials, seed=seed, path=path)["error"].values

    return simulate, PATH_NAMES[chosen]


def adaptive_monte_carlo(scenario: Scenario, *, path: str = "auto", **options) -> CalibrationMonteCarlo:
    """JCGM 101 7.9.4 adaptive Monte Carlo of the scenario's calibration (outputs: the 39 errors).

    Parameters
    ----------
    scenario : Scenario
    path : {"auto", "sample", "segment"}
        Simulation path.
    **options
        ``digits``, ``trials_per_block``, ``max_trials``, ``seed``, ``tolerance``, ``parameters``,
        ``coverage_probability``, ``progress`` of
        :func:`plansim.uncertainty.monte_carlo.calibration_monte_carlo`.
    """
    from plansim.uncertainty.monte_carlo import calibration_monte_carlo

    if not isinstance(scenario, Scenario):
        raise TypeError(f"scenario = {scenario!r}: expected a plansim.config.Scenario")
    simulate, path_name = error_simulator(scenario, path)
    return calibration_monte_carlo(simulate, scenario, path=path_name, **options)


def validate(scenario: Scenario | str = "jjf2003", claims=None, *, path: str = "auto", **options) -> ValidationReport:
    """``plansim validate``: GUM budget, adaptive MCM, JCGM 101 §8 validation and coverage of the truth.

    Parameters
    ----------
    scenario : Scenario or str
        A scenario, a built-in name or a TOML path.
    claims : mapping of parameter name -> Claim, optional
        Default: the Appendix A budgets as printed.
    path : {"auto", "sample", "segment"}
        Simulation path of the Monte Carlo.
    **options
        The keyword arguments of :func:`plansim.uncertainty.validation.validate` (``digits``,
        ``trials_per_block``, ``max_trials``, ``seed``, ``tolerance_fraction``,
        ``coverage_probability``, ``joint_parameters``, ``monitor``, ``progress``).
    """
    from plansim.uncertainty.validation import validate as validate_scenario

    sc = _scenario_of(scenario)
    simulate, path_name = error_simulator(sc, path)
    return validate_scenario(sc, simulate, claims, path=path_name, **options)
